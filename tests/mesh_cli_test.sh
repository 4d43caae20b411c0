#!/usr/bin/env bash
# Issue 35 as a user meets it: `sdfc mesh` with default flags into a path
# with spaces, standard error a log file (not a terminal). The report says
# "closed manifold" only when the file is one by position, says where and what
# to do when it is not, and the log gets at most a progress line every few
# seconds (it had one per 10% per stage: ~30 for a one-second mesh).
# Usage: mesh_cli_test.sh <sdfc>
set -uo pipefail
sdfc=$1
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir "$work/out dir"
failures=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }

# The castle without its lawn (a plane is unbounded).
grep -v 'plane(normal: \[0, 1, 0\], offset: 0, material: lawn)' "$root/examples/castle.sdf" >"$work/castle.sdf"
start=$(date +%s%N)
"$sdfc" mesh "$work/castle.sdf" -o "$work/out dir/castle.stl" --resolution 64 >"$work/report" 2>"$work/log"
code=$?
millis=$(( ($(date +%s%N) - start) / 1000000 ))
cat "$work/report"
[ "$code" -eq 0 ] || fail "castle: exit $code"
grep -q 'topology: closed manifold' "$work/report" || fail "castle at 64 is not reported closed"
grep -q 'welded: ' "$work/report" || fail "castle at 64: no weld reported (the roof ridge has coincident vertices)"
progress=$(grep -c '^sdfc: .*%$' "$work/log")
# One line per 3 s at most, and a first line only after 3 s.
allowed=$(( millis / 3000 ))
if [ "$progress" -gt "$allowed" ]; then
  fail "castle: $progress progress lines in ${millis} ms (at most $allowed):"
  cat "$work/log" >&2
fi

# Two cubes sharing an edge touch in the scene: never "closed"; the report
# says where and what a finer grid would do.
printf 'scene { union { translate([-0.5, -0.5, 0]) { box(size: [1, 1, 1]) }\n  translate([0.5, 0.5, 0]) { box(size: [1, 1, 1]) } } }\n' >"$work/edge.sdf"
"$sdfc" mesh "$work/edge.sdf" -o "$work/out dir/edge.glb" --resolution 20 >"$work/report" 2>"$work/log"
code=$?
cat "$work/report"
[ "$code" -eq 0 ] || fail "edge: exit $code"
grep -q 'topology: not a closed manifold' "$work/report" || fail "cubes on an edge reported closed"
grep -q 'note: near .*--resolution 40' "$work/report" || fail "cubes on an edge: no note saying where and what to try"
[ -s "$work/log" ] && { fail "edge: a 0.1 s mesh wrote to the log:"; cat "$work/log" >&2; }

[ "$failures" -eq 0 ] && echo "mesh_cli: all passed"
exit $((failures > 0))
