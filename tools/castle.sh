#!/usr/bin/env bash
# Sets up and builds (tools/setup.sh), then renders the castle to castle.png.
set -euo pipefail
cd "$(dirname "$0")/.."
./tools/setup.sh
./build/cli/sdfc render examples/castle.sdf -o castle.png "$@"
echo "castle.png written"
