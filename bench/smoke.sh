#!/bin/sh
# CI smoke test of the benchmark: a reduced run (tiny images, 2 configurations,
# 1 scene for convergence, every hard case for geometry) that must finish in
# under 3 minutes and exits non-zero when a bound in run.py SMOKE_BOUNDS fails.
# Usage: bench/smoke.sh path/to/sdfc
set -eu
here=$(cd "$(dirname "$0")" && pwd)
sdfc=${1:-$here/../build/cli/sdfc}
out=$(mktemp -d "${TMPDIR:-/tmp}/sdfc_bench_smoke.XXXXXX")
trap 'rm -rf "$out"' EXIT
# Debian's python3 with python3-numpy / python3-matplotlib (apt), not a pyenv shim.
py=/usr/bin/python3
[ -x "$py" ] || py=python3
"$py" "$here/run.py" --smoke --sdfc "$sdfc" --out "$out" --cache "$out/cache"
