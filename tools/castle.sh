#!/usr/bin/env bash
# Sets up and builds the program (tools/setup.sh sdfc: not the tests, which
# tools/test.sh builds), then renders the castle to castle.png.
set -euo pipefail
cd "$(dirname "$0")/.."
./tools/setup.sh sdfc
./build/cli/sdfc render examples/castle.sdf -o castle.png "$@"
echo "castle.png written"
