#!/usr/bin/env bash
# The Python package as a user installs it: `pip wheel .` (scikit-build-core and
# pybind11 from PyPI, in pip's isolated build environment), the wheel installed
# into a fresh virtual environment with numpy and pytest, and python/tests run
# there against the command line in build/ (tools/setup.sh builds it first).
set -euo pipefail
cd "$(dirname "$0")/.."
root="$PWD"
python="${PYTHON:-/usr/bin/python3}"
work="$(mktemp -d "${TMPDIR:-/tmp}/sdfc-wheel.XXXXXX")"
trap 'rm -rf "$work"' EXIT
start=$(date +%s)
"$python" -m venv "$work/venv"
pip="$work/venv/bin/pip"
"$pip" --disable-pip-version-check -q wheel . -w "$work/dist" --no-deps
built=$(date +%s)
"$pip" --disable-pip-version-check -q install "$work"/dist/sdfc-*.whl numpy pytest
cd "$work"  # not the checkout: `import sdfc` must be the installed one
# An installed wheel uses the system's Vulkan driver (build/'s bundled lavapipe is
# not beside it): the command line it is compared with bit for bit must too.
SDFC="$root/build/cli/sdfc" SDFC_DRIVER=system XDG_CACHE_HOME="$work/cache" \
  "$work/venv/bin/python" -m pytest -q -p no:cacheprovider "$root/python/tests"
echo "python wheel check: wheel built in $((built - start)) s, installed and tested in $(( $(date +%s) - built )) s"
