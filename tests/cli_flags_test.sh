#!/usr/bin/env bash
# Issue 28: every float flag of every subcommand refuses NaN, infinities and
# values out of its range (CLI::Range lets NaN through); flags a shard cannot
# honour are refused; `farm submit --video` needs ffmpeg before it submits;
# `sdfc merge` refuses to overwrite its inputs and reports damaged shards with
# one exit code (2) and the file's name. Usage: cli_flags_test.sh <sdfc>
set -uo pipefail
sdfc=$1
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/sdfc flags.XXXXXX")  # a space in every path
trap 'rm -rf "$work"' EXIT
failures=0

. "$root/tests/cli_expect.sh"

scene=$root/examples/morph.sdf
printf 'scene { sphere(radius: 1) }\n' >"$work/s.sdf"

# Float flags: NaN, infinities, float32 overflow and out-of-range values are
# usage errors before any work (--exposure nan once wrote an all-black PNG).
for v in nan inf -inf 1e39 0x10; do
  expect 2 "--exposure: expects a number in \[-64, 64\], got '$v'" -- "$sdfc" render "$scene" --exposure "$v" -o "$work/x.png"
  expect 2 "--exposure" -- "$sdfc" view "$scene" --exposure "$v"
  expect 2 "--voxel-size" -- "$sdfc" mesh "$work/s.sdf" --voxel-size "$v" -o "$work/x.stl"
  for flag in --adaptive-share --adaptive-cap --adaptive-power --adaptive-cost-offset --fps; do
    expect 2 "$flag" -- "$sdfc" render "$scene" --adaptive $flag "$v" -o "$work/x.png"
  done
  expect 2 "--denoise-select" -- "$sdfc" render "$scene" --denoise nlr --denoise-select "0.7,$v" -o "$work/x.png"
  expect 2 "--fps" -- "$sdfc" farm submit "$scene" --shards 2 --frames 0-1 --fps "$v" -o "$work/job" --dry-run
done
expect 2 "--exposure: expects a number in \[-64, 64\], got '65'" -- "$sdfc" render "$scene" --exposure 65 -o "$work/x.png"
# --time is checked by every subcommand that takes it (view and farm submit too).
for t in nan inf 1e39; do
  expect 2 "--time must be a finite number" -- "$sdfc" view "$scene" --time "$t"
  expect 2 "--time must be a finite number" -- "$sdfc" farm submit "$scene" --shards 2 --time "$t" -o "$work/job" --dry-run
  expect 2 "--time must be a finite number" -- "$sdfc" mesh "$work/s.sdf" --time "$t" -o "$work/x.stl"
done
[ ! -e "$work/job" ] || fail "a refused submit created its job directory"
# --voxel-size 0 and negative sizes were ignored (the --resolution grid was used).
for v in 0 -1 -0; do
  expect 2 "--voxel-size: expects a number in \(0, " -- "$sdfc" mesh "$work/s.sdf" --voxel-size "$v" -o "$work/x.stl"
done
expect 2 "--resolution" -- "$sdfc" mesh "$work/s.sdf" --resolution 1025 -o "$work/x.stl"
expect 0 "" -- "$sdfc" mesh "$work/s.sdf" --voxel-size 0.25 -o "$work/x.stl" -q

# Flags that act on the finished image do not apply to a shard: refused, not dropped.
for flags in "--denoise nlr" "--denoise-select 1" "--denoise-aovs centre" "--exposure 1" "--aces"; do
  # shellcheck disable=SC2086
  expect 2 "does not apply to --shards" -- "$sdfc" render "$scene" --shards 2 --shard-index 0 $flags -o "$work/shards"
done
[ ! -e "$work/shards" ] || fail "a refused shard created its directory"

# farm submit --video without ffmpeg: refused before anything is written (the
# merge job once failed at the very end, after every shard had rendered).
mkdir "$work/bin"
expect 2 "--video needs ffmpeg on PATH" -- env PATH="$work/bin" "$sdfc" farm submit "$scene" --shards 2 \
  --frames 0-1 --video "$work/a.mp4" -o "$work/job" --dry-run
[ ! -e "$work/job" ] || fail "a refused --video submit created its job directory"
printf '#!/bin/sh\nexit 0\n' >"$work/bin/ffmpeg"
chmod +x "$work/bin/ffmpeg"
expect 0 "" -- env PATH="$work/bin" "$sdfc" farm submit "$scene" --shards 2 --frames 0-1 --video "$work/a.mp4" \
  -o "$work/job" --dry-run

# sdfc merge: two real shards of a small still.
shards="$work/shards dir"
for i in 0 1; do
  "$sdfc" render "$work/s.sdf" --size 16x12 --spp 64 --shards 2 --shard-index $i -o "$shards" -q ||
    fail "shard $i did not render"
done
cp "$shards/shard_00000.exr" "$work/keep.exr"
# An output that is one of the inputs, by any spelling or link, is refused.
ln -s "$shards/shard_00000.exr" "$work/link.exr"
for out in "$shards/shard_00000.exr" "$shards/./shard_00000.exr" "$work/link.exr"; do
  expect 2 "is one of the shards being merged" -- "$sdfc" merge "$shards" -o "$out"
done
expect 2 "is one of the shards being merged" -- "$sdfc" merge "$shards/shard_00000.exr" "$shards/shard_00001.exr" -o "$work/link.exr"
cmp -s "$shards/shard_00000.exr" "$work/keep.exr" || fail "merge overwrote one of its inputs"
cp "$work/keep.exr" "$shards/shard_00000.exr"  # the cases below stand alone even when that failed
expect 0 "" -- "$sdfc" merge "$shards" -o "$work/merged.exr" -q
# As render: merge creates no folders (it made nope/deeper).
expect 4 "the folder '$work/nope/deeper' does not exist" -- "$sdfc" merge "$shards" -o "$work/nope/deeper/x.exr"
[ ! -e "$work/nope" ] || fail "merge created the folders of -o"

# Damaged shards: one exit code (2), the file named, no raw library text alone.
# edit_attribute FILE NAME VALUE: a copy of FILE with header attribute NAME set to VALUE.
edit_attribute() {
  python3 - "$1" "$2" "$3" <<'PY'
import struct, sys
path, name, value = sys.argv[1], sys.argv[2].encode(), sys.argv[3].encode()
data = open(path, "rb").read()
key = name + b"\0string\0"
at = data.index(key) + len(key)
size = struct.unpack("<i", data[at:at + 4])[0]
data = data[:at] + struct.pack("<i", len(value)) + value + data[at + 4 + size:]
open(path, "wb").write(data)
PY
}
bad=$work/bad
for case in "sdfc.frame zz" "sdfc.frame 1x" "sdfc.spp 4294967297" "sdfc.width 0" "sdfc.time nan" "sdfc.seed -3"; do
  rm -rf "$bad" && mkdir "$bad" && cp "$shards"/shard_*.exr "$bad/"
  set -- $case
  edit_attribute "$bad/shard_00001.exr" "$1" "$2"
  expect 2 "shard_00001.exr: attribute '$1' is not a" -- "$sdfc" merge "$bad" -o "$work/m.exr"
done
rm -rf "$bad" && mkdir "$bad" && cp "$shards"/shard_*.exr "$bad/"
size=$(stat -c %s "$bad/shard_00001.exr")
truncate -s $((size - size / 4)) "$bad/shard_00001.exr"
expect 2 "merge: .*shard_00001.exr: the pixel data is damaged or cut short" -- "$sdfc" merge "$bad" -o "$work/m.exr"

if [ "$failures" -ne 0 ]; then
  echo "$failures failure(s)" >&2
  exit 1
fi
echo "cli_flags: all cases passed"
