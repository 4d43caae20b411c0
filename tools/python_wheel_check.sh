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
# The wheel carries build/lavapipe-25's driver when tools/setup.sh fetched it, and
# the installed package renders with it by default, as the command line does:
# compared bit for bit with no SDFC_DRIVER set, then both on the system's driver.
expect=0
[ -f "$root/build/lavapipe-25/lvp_icd.x86_64.json" ] && expect=1
"$work/venv/bin/python" -c 'import sdfc; print("python wheel check: the installed package renders with", sdfc.driver())'
env -u SDFC_DRIVER -u SDFC_LAVAPIPE SDFC="$root/build/cli/sdfc" SDFC_EXPECT_WHEEL_DRIVER=$expect \
  XDG_CACHE_HOME="$work/cache" "$work/venv/bin/python" -m pytest -q -p no:cacheprovider "$root/python/tests"
SDFC="$root/build/cli/sdfc" SDFC_DRIVER=system XDG_CACHE_HOME="$work/cache" \
  "$work/venv/bin/python" -m pytest -q -p no:cacheprovider "$root/python/tests/test_sdfc.py" \
  -k "driver or render_bit_equal"
echo "python wheel check: wheel built in $((built - start)) s, installed and tested in $(( $(date +%s) - built )) s"
