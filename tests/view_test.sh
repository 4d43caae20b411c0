#!/bin/sh
# Runs tests/view_test.py under its own Xvfb, so `ctest` works on a headless
# machine with no X server running. xvfb-run -a picks a free display number;
# it needs only /tmp, /proc and /dev (also inside a chroot).
# Usage: tests/view_test.sh path/to/sdfc
set -eu
here=$(cd "$(dirname "$0")" && pwd)
py=/usr/bin/python3
[ -x "$py" ] || py=python3
exec xvfb-run -a -s "-screen 0 1024x768x24 -nolisten tcp" "$py" "$here/view_test.py" "$1"
