#!/usr/bin/env bash
# Issue 18: the command line's answers to bad input, by exit code (0 ok,
# 1 scene errors, 2 usage, 4 files) and message; each case is decided before
# any rendering (no device is needed for them). Usage: cli_bad_input_test.sh <sdfc>
set -uo pipefail
sdfc=$1
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0

. "$root/tests/cli_expect.sh"

scene=$root/examples/morph.sdf
printf 'let r = 1\nscene { sphere(radius: r) }\n' >"$work/r.sdf"

# --time that float32 cannot hold: usage errors before any work.
for t in nan inf -inf 1e39; do
  expect 2 "--time must be a finite number" -- "$sdfc" render "$scene" --time "$t" -o "$work/x.png"
  expect 2 "--time must be a finite number" -- "$sdfc" eval "$scene" --time "$t"
done
# Frame counts are counted before any list is built.
expect 2 "gives 1e\+06 frames; at most 100000" -- "$sdfc" render "$scene" --frames 0-999999 -o "$work/x.png"
expect 2 "--frames expects A-B" -- "$sdfc" render "$scene" --frames 0-1e999 -o "$work/x.png"
# The old times form A-B:step is refused (issue 29: one meaning of --frames).
expect 2 "--frames takes frame numbers A-B at --fps" -- "$sdfc" render "$scene" --frames 0-1e9:1e-9 -o "$work/x.png"
# -D takes a plain decimal number.
for v in 0x10 inf 1e999 nan 1,5; do
  expect 2 "-D expects name=number with a plain decimal number" -- "$sdfc" check "$work/r.sdf" -D "r=$v"
done
expect 0 "" -- "$sdfc" check "$work/r.sdf" -D r=+1.5e0
# Long numbers are refused cleanly (std::regex recursed once per character
# and overflowed the stack: exit 139).
digits=$(head -c 30000 /dev/zero | tr '\0' 7)
ones=$(head -c 100000 /dev/zero | tr '\0' 1)
for cmd in check eval render; do
  out=()
  [ "$cmd" = render ] && out=(-o "$work/x.png")
  expect 2 "-D expects name=number" -- "$sdfc" "$cmd" "$work/r.sdf" -D "r=$digits" "${out[@]}"
done
expect 0 "" -- "$sdfc" check "$work/r.sdf" -D "r=0.$ones"
echo "0 0 0" >"$work/origin.txt"
expect 0 "" -- "$sdfc" eval "$work/r.sdf" -D "r=0.$ones" --points "$work/origin.txt"
expect 2 "--frames takes frame numbers A-B at --fps" -- "$sdfc" render "$scene" --frames "1-2:0.$ones" -o "$work/x.png"
expect 2 "--spp" -- "$sdfc" render "$scene" --spp "$digits" -o "$work/x.png"
expect 2 "--size" -- "$sdfc" render "$scene" --size "${digits}x1" -o "$work/x.png"
# A directory as the scene: unreadable input.
expect 4 "it is a directory, not a scene file" -- "$sdfc" check "$work"
# A FIFO or a device as the scene: refused at once, not a hang or 4 GB read
# (issue 47 item 18); every command that reads a scene goes through one check.
mkfifo "$work/pipe.sdf"
expect 4 "it is not a regular file" -- timeout 10 "$sdfc" check "$work/pipe.sdf"
expect 4 "it is not a regular file" -- timeout 10 "$sdfc" render "$work/pipe.sdf" -o "$work/x.png"
expect 4 "it is not a regular file" -- timeout 10 "$sdfc" eval "$work/pipe.sdf" --points "$work/origin.txt"
expect 4 "it is not a regular file" -- timeout 10 "$sdfc" fmt "$work/pipe.sdf"
expect 4 "it is not a regular file" -- timeout 10 "$sdfc" export "$work/pipe.sdf" -o "$work/x.html"
expect 4 "it is not a regular file" -- timeout 10 "$sdfc" check /dev/zero
# A UTF-8 byte order mark before the first statement is not an error.
printf '\xef\xbb\xbfscene { sphere(radius: 1) }\n' > "$work/bom.sdf"
expect 0 "" -- "$sdfc" check "$work/bom.sdf"
# Every file read through an import follows the scene file's rule, with the
# import statement's file:line:col (issue 47 item 18: a 300 MB one-line
# import ran to std::bad_alloc with no file or line). Sparse files: nothing
# is read, the sizes are refused first.
mkdir "$work/imp"
truncate -s 300M "$work/imp/big.sdf"
printf 'let a = 1\nimport "big.sdf" as b\nscene { sphere(radius: 1) }\n' >"$work/imp/one.sdf"
expect 1 "one.sdf:2:8: error: cannot import '.*big.sdf': it is 300 MiB, more than a scene file's 256 MiB" -- "$sdfc" check "$work/imp/one.sdf"
grep -q '^import "big.sdf" as b$' "$work/err" || fail "the import error does not show its line"
# half1.sdf is one comment (read: 130 MiB of a sparse file's zeros after //).
printf '//' >"$work/imp/half1.sdf"
truncate -s 130M "$work/imp/half1.sdf"
truncate -s 130M "$work/imp/half2.sdf"
printf 'import "half1.sdf" as h\nimport "half2.sdf" as i\nscene { sphere(radius: 1) }\n' >"$work/imp/two.sdf"
expect 1 "two.sdf:2:8: error: cannot import '.*half2.sdf': it is 130 MiB, and with the 130 MiB already read the scene and its imports would be more than 256 MiB" -- timeout 60 "$sdfc" check "$work/imp/two.sdf"
mkfifo "$work/imp/pipe.sdf"
printf 'import "pipe.sdf" as p\nimport "/dev/zero" as z\nscene { sphere(radius: 1) }\n' >"$work/imp/dev.sdf"
expect 1 "dev.sdf:1:8: error: cannot import '.*pipe.sdf': it is not a regular file" -- timeout 10 "$sdfc" check "$work/imp/dev.sdf"
grep -q "dev.sdf:2:8: error: cannot import '/dev/zero': it is not a regular file" "$work/err" || fail "/dev/zero as an import"
# The output directory is checked before compiling or rendering.
expect 4 "cannot write '$work/missing/x.png': the folder '$work/missing' does not exist" -- "$sdfc" render "$scene" -o "$work/missing/x.png"
expect 4 "it is a directory" -- "$sdfc" compile "$scene" -o "$work"
# Devices and FIFOs are written in place, never replaced by a regular file.
expect 4 "cannot write '/dev/full': No space left on device" -- "$sdfc" compile "$scene" -o /dev/full
mkfifo "$work/pipe.glsl"
cat "$work/pipe.glsl" >"$work/from_pipe" &
expect 0 "" -- "$sdfc" compile "$scene" -o "$work/pipe.glsl"
wait
[ -p "$work/pipe.glsl" ] && [ -s "$work/from_pipe" ] || { echo "FAIL: FIFO replaced or empty" >&2; failures=$((failures + 1)); }
# '-o -' writes to standard output (SPIR-V too, when it is not a terminal).
"$sdfc" compile "$scene" -o - --emit spv >"$work/stdout.spv" 2>"$work/err" &&
  [ "$(head -c 4 "$work/stdout.spv" | od -An -tx4 | tr -d ' ')" = 07230203 ] ||
  { echo "FAIL: --emit spv -o - did not write SPIR-V" >&2; failures=$((failures + 1)); }
# A stale temporary beside the output does not get in the way.
mkdir "$work/out.glsl.tmp"
expect 0 "" -- "$sdfc" compile "$scene" -o "$work/out.glsl"
# Checked scenes that once failed in glslang are scene errors now.
expect 1 "at most 16 'light's" -- "$sdfc" compile "$root/fuzz/regressions/issue18_seventeen_lights.sdf" -o "$work/l.glsl"
expect 1 "beyond the range of the shader's float32 numbers" -- "$sdfc" compile "$root/fuzz/regressions/issue18_sun_direction_overflow.sdf" -o "$work/s.glsl"

# No command writes over one of its inputs (the scene, an import, a data
# file), by file identity: export and compile once overwrote the scene.
mkdir "$work/in"
printf 'let post = sphere(radius: 1)\n' >"$work/in/lib.sdf"
printf '0 0 0\n2 0 0\n' >"$work/in/p.csv"
printf 'import "lib.sdf" as l\nscene { l.post instances(positions: file("p.csv")) { sphere(radius: 0.1) } }\n' >"$work/in/s.sdf"
cp "$work/in/s.sdf" "$work/in/s.orig"
ln "$work/in/s.sdf" "$work/in/hard.glsl"
ln -s s.sdf "$work/in/soft.html"
expect 2 "-o must end in .html, got '$work/in/s.sdf'" -- "$sdfc" export "$work/in/s.sdf" -o "$work/in/s.sdf"
expect 2 "the output .* is the scene being read" -- "$sdfc" compile "$work/in/s.sdf" --emit glsl -o "$work/in/s.sdf"
expect 2 "the output .* is the scene being read" -- "$sdfc" compile "$work/in/s.sdf" --emit glsl -o "$work/in/hard.glsl"
expect 2 "the output .* is the scene being read" -- "$sdfc" export "$work/in/s.sdf" -o "$work/in/soft.html"
expect 2 "the output .*/in/../in/s.sdf' is the scene being read" -- "$sdfc" compile "$work/in/s.sdf" --emit ir -o "$work/in/../in/s.sdf"
expect 2 "lib.sdf', which the scene imports" -- "$sdfc" compile "$work/in/s.sdf" --emit glsl -o "$work/in/lib.sdf"
expect 2 "p.csv', which the scene reads" -- "$sdfc" compile "$work/in/s.sdf" --emit ir -o "$work/in/p.csv"
# render: a texture is an input too (checked before any rendering), and a
# sequence's frames by their own names.
cp "$root/examples/textures/tiles.png" "$work/in/tiles.png"
cp "$root/examples/textures/tiles.png" "$work/in/tiles_0003.png"
for t in tiles tiles_0003; do
  printf 'let wood = diffuse(albedo: texture(file: "%s.png", projection: triplanar, size: 0.5))\nscene { sphere(radius: 1, material: wood) }\n' $t >"$work/in/$t.sdf"
done
expect 2 "tiles.png', which the scene reads" -- "$sdfc" render "$work/in/tiles.sdf" -o "$work/in/tiles.png" --size 8x8 --spp 1
expect 2 "tiles_0003.png', which the scene reads" -- "$sdfc" render "$work/in/tiles_0003.sdf" -o "$work/in/tiles.png" --frames 3-3 --size 8x8 --spp 1
cmp -s "$work/in/tiles.png" "$root/examples/textures/tiles.png" || fail "the texture was overwritten"
cmp -s "$work/in/tiles_0003.png" "$root/examples/textures/tiles.png" || fail "the frame-named texture was overwritten"
# -o names no frame of a sequence: tiles.png is not written, tiles_0000.png is.
expect 0 "" -- "$sdfc" render "$work/in/tiles.sdf" -o "$work/in/tiles.png" --frames 0-0 --size 8x8 --spp 1 -q
[ -s "$work/in/tiles_0000.png" ] || fail "render --frames 0-0 wrote no tiles_0000.png"
cmp -s "$work/in/s.sdf" "$work/in/s.orig" || fail "the scene was overwritten"
[ "$(cat "$work/in/lib.sdf")" = "let post = sphere(radius: 1)" ] || fail "the import was overwritten"
[ "$(head -c 5 "$work/in/p.csv")" = "0 0 0" ] || fail "the point file was overwritten"
# export's -o ends in .html (.glsl for Shadertoy), as render's and mesh's have their extensions.
expect 2 "-o must end in .html, got '$work/in/noext'" -- "$sdfc" export "$work/in/s.sdf" -o "$work/in/noext"
expect 2 "-o must end in .glsl" -- "$sdfc" export "$work/in/s.sdf" -o "$work/in/x.html" --target shadertoy
[ ! -e "$work/in/noext" ] || fail "export -o noext wrote a file"
expect 0 "" -- "$sdfc" compile "$work/in/s.sdf" --emit glsl -o "$work/in/out.glsl"

# A full disk (a 64 KiB tmpfs, when this machine lets us mount one): the
# image write fails with exit 4 and the previous file stays whole.
full=$work/full
mkdir "$full"
if mount -t tmpfs -o size=64k tmpfs "$full" 2>/dev/null; then
  printf 'keep' >"$full/x.pfm"
  head -c 40000 /dev/zero >"$full/filler"
  expect 4 "No space left on device" -- "$sdfc" compile "$scene" -o "$full/x.pfm" --emit glsl
  [ "$(cat "$full/x.pfm")" = keep ] || { echo "FAIL: previous file damaged" >&2; failures=$((failures + 1)); }
  # The case from the issue: a PNG render to a full disk once exited 0 and
  # left a truncated file.
  printf 'keep' >"$full/x.png"
  expect 4 "No space left on device" -- "$sdfc" render "$scene" --size 256x256 --spp 1 -q -o "$full/x.png"
  [ "$(cat "$full/x.png")" = keep ] || { echo "FAIL: previous PNG damaged" >&2; failures=$((failures + 1)); }
  [ "$(ls -A "$full" | wc -l)" -eq 3 ] || { echo "FAIL: temporary left: $(ls -A "$full")" >&2; failures=$((failures + 1)); }
  umount "$full"
else
  echo "skip: cannot mount a tmpfs here (full-disk writes are also covered by BadInputWrites.AFullDiskFailsEveryFormatAndKeepsThePreviousFile)"
fi

# Shards: -o names the folder that holds them. A file there, or a folder that
# cannot be made, is an unwritable output (exit 4) in sdfc's words, before any
# rendering (issue 47 item 18: "filesystem error: cannot create directories").
printf 'x' >"$work/afile"
expect 4 "sdfc: error: cannot write shards into '$work/afile': it is a file, not a folder" -- "$sdfc" render "$work/r.sdf" --shards 4 --shard-index 0 --size 8x8 --spp 64 -o "$work/afile"
expect 4 "sdfc: error: cannot write shards into '$work/afile/sub': the folder cannot be made \(Not a directory\)" -- "$sdfc" render "$work/r.sdf" --shards 4 --shard-index 0 --size 8x8 --spp 64 -o "$work/afile/sub"
if [ "$(id -u)" != 0 ]; then
  mkdir "$work/readonly" && chmod a-w "$work/readonly"
  expect 4 "sdfc: error: cannot write shards into '$work/readonly/s': the folder cannot be made \(Permission denied\)" -- "$sdfc" render "$work/r.sdf" --shards 4 --shard-index 0 --size 8x8 --spp 64 -o "$work/readonly/s"
  expect 4 "sdfc: error: cannot write shards into '$work/readonly': the folder is not writable" -- "$sdfc" render "$work/r.sdf" --shards 4 --shard-index 0 --size 8x8 --spp 64 -o "$work/readonly"
  chmod u+w "$work/readonly"
fi
grep -q "filesystem error" "$work/err" && fail "library text reached the user"
# merge: a shard that is a link to itself is a damaged shard (exit 2), named,
# whether found in a folder or given by name ("Too many levels of symbolic
# links", exit 4, before).
mkdir "$work/loop"
ln -s shard_00000.exr "$work/loop/shard_00000.exr"
expect 2 "sdfc: error: merge: $work/loop/shard_00000.exr: a symbolic link that loops" -- "$sdfc" merge "$work/loop" -o "$work/m.exr"
expect 2 "sdfc: error: merge: $work/loop/shard_00000.exr: a symbolic link that loops" -- "$sdfc" merge "$work/loop/shard_00000.exr" -o "$work/m.exr"
ln -s nothing.exr "$work/loop/shard_00001.exr"
expect 2 "sdfc: error: merge: $work/loop/shard_00001.exr: a symbolic link to nothing" -- "$sdfc" merge "$work/loop/shard_00001.exr" -o "$work/m.exr"
mkfifo "$work/loop/fifo.exr"
expect 2 "sdfc: error: merge: $work/loop/fifo.exr: not a regular file" -- timeout 10 "$sdfc" merge "$work/loop/fifo.exr" -o "$work/m.exr"
# --shards more than the passes: the message's arithmetic is what the
# renderer does (32 spp at 18 a pass were "2 passes of 18 samples").
expect 2 "32 spp are 2 passes \(18 \+ 14 samples\); a shard takes whole passes, so use at most 2 shards" -- "$sdfc" render "$work/r.sdf" --shards 3 --shard-index 0 --spp 32 --size 232x232 -o "$work/sh"

echo "$failures failure(s)"
[ "$failures" -eq 0 ]
