#!/bin/bash
# `sdfc render --layers --shards` and `sdfc merge` (issue 33, docs/farm.md,
# docs/layers.md): a merged farm render's layered EXR equals a single
# `render --layers` byte for byte, whatever the shard sizes, the slicings mixed
# and the order of the shards on the command line; a still and an animation.
# Bad input is refused with exit 2 and the file named: layered and plain shards
# mixed, another scene, a missing shard, an old shard format, a damaged shard 0,
# a layered merge into a PNG. Paths with spaces throughout.
# Usage: tests/layers_farm_test.sh path/to/sdfc
sdfc=$1
work=$(mktemp -d "${TMPDIR:-/tmp}/sdfc_layers_farm.XXXXXX")
trap 'rm -rf "$work"' EXIT
failures=0
. "$(dirname "$0")/cli_expect.sh"
export SDFC_VALIDATION=1

dir="$work/a job"
mkdir -p "$dir"
scene="$dir/three shapes.sdf"
# The loop budget of this scene cuts its passes at 56 samples: 150 spp are 3
# passes (56, 56, 38). The sphere moves with time, for the animation.
cat >"$scene" <<'EOF'
render(size: [48, 27], spp: 150, bounces: 2)
camera(position: [0, 1.2, 4.5], target: [0, 0.5, 0], fov: 40)
sky(top: [0.4, 0.6, 1.0], bottom: [1, 1, 1])
sun(direction: [-0.4, 1, 0.3], angle: 3, strength: 2)
let ground = diffuse(albedo: [0.5, 0.5, 0.5])
scene {
  plane(normal: [0, 1, 0], offset: 0, material: ground)
  translate([-0.6 + 0.3 * time, 0.5, 0]) { sphere(radius: 0.5, material: diffuse(albedo: [0.8, 0.3, 0.25])) }
  translate([0.7, 0.35, 0.2]) { box(size: 0.7, material: ground) }
}
EOF

shard() {  # shard DIR SLICES INDEX [flags...]
  local out=$1 slices=$2 index=$3
  shift 3
  "$sdfc" render "$scene" --layers -q --shards "$slices" --shard-index "$index" -o "$out" "$@" 2>"$work/err" ||
    { fail "shard $index of $slices ($*) failed: $(cat "$work/err")"; return; }
  [ -s "$work/err" ] && fail "shard $index of $slices printed: $(cat "$work/err")"
}
same() {  # same A B WHAT
  if cmp -s "$1" "$2"; then echo "ok: $3"; else fail "$3: $1 and $2 differ"; fi
}

"$sdfc" render "$scene" --layers -q -o "$dir/single.exr" || fail "render --layers failed"

# Three shards of one pass each, merged in another order than their samples'.
for i in 0 1 2; do shard "$dir/three" 3 $i; done
expect 0 "merged 3 shards into 1 image \(48x27, 150 spp\)" -- "$sdfc" merge "$dir/three/shard_00002.exr" \
  "$dir/three/shard_00000.exr" "$dir/three/shard_00001.exr" -o "$dir/merged three.exr"
same "$dir/single.exr" "$dir/merged three.exr" "3 shards given out of order merge to the single render's layers"

# Unequal shards: two slices are [0, 56) and [56, 150); and slicings mixed:
# [56, 150) of two slices with [0, 56) of three.
for i in 0 1; do shard "$dir/two" 2 $i; done
expect 0 "" -- "$sdfc" merge "$dir/two" -o "$dir/merged two.exr"
same "$dir/single.exr" "$dir/merged two.exr" "unequal shards (56 and 94 samples) merge to the single render's layers"
expect 0 "" -- "$sdfc" merge "$dir/two/shard_00001.exr" "$dir/three/shard_00000.exr" -o "$dir/merged mixed.exr"
same "$dir/single.exr" "$dir/merged mixed.exr" "2- and 3-slice shards mixed merge to the single render's layers"

# An animation: 2 frames x 2 shards, each frame's file equal to render --frames'.
"$sdfc" render "$scene" --layers -q --size 32x18 --frames 0-1 --fps 4 -o "$dir/anim.exr" ||
  fail "render --layers --frames failed"
for i in 0 1 2 3; do shard "$dir/anim shards" 2 $i --size 32x18 --frames 0-1 --fps 4; done
mkdir "$dir/merged"  # merge creates no folders, as render
expect 0 "merged 4 shards into 2 frames" -- "$sdfc" merge "$dir/anim shards" --frames 0-1 --png \
  -o "$dir/merged/anim.exr"
for f in 0000 0001; do
  same "$dir/anim_$f.exr" "$dir/merged/anim_$f.exr" "frame $f of 2 x 2 shards equals render --layers --frames"
  [ -s "$dir/merged/anim_$f.png" ] || fail "merge --png wrote no $dir/merged/anim_$f.png"
done
cmp -s "$dir/merged/anim_0000.exr" "$dir/merged/anim_0001.exr" && fail "the frames are the same image"

# The layers hold the raw mean: a shard refuses the denoiser, as render --layers does.
expect 2 "error: --layers does not go with --denoise" -- "$sdfc" render "$scene" --layers --denoise nlm \
  --shards 3 --shard-index 0 -o "$dir/denoised"

# Layered and plain shards mixed.
mkdir -p "$dir/mixed"
"$sdfc" render "$scene" -q --shards 3 --shard-index 1 -o "$dir/plain" || fail "plain shard failed"
cp "$dir/three/shard_00000.exr" "$dir/three/shard_00002.exr" "$dir/mixed/"
cp "$dir/plain/shard_00001.exr" "$dir/mixed/"
expect 2 "merge: .*mixed/shard_00001.exr does not belong with .*: .*mixed/shard_00000.exr is a shard of a --layers render and .*mixed/shard_00001.exr is not" \
  -- "$sdfc" merge "$dir/mixed" -o "$dir/m.exr"

# Another scene (the box moved).
sed 's/0.7, 0.35, 0.2/0.6, 0.35, 0.2/' "$scene" >"$dir/other scene.sdf"
"$sdfc" render "$dir/other scene.sdf" --layers -q --shards 3 --shard-index 1 -o "$dir/other" ||
  fail "other scene's shard failed"
expect 2 "merge: .*other/shard_00001.exr does not belong with .*three/shard_00000.exr: scene_hash" \
  -- "$sdfc" merge "$dir/three/shard_00000.exr" "$dir/other/shard_00001.exr" "$dir/three/shard_00002.exr" \
  -o "$dir/m.exr"

# A missing shard.
expect 2 "merge: missing samples \[56, 112\) of the still \(before .*shard_00002.exr\)" \
  -- "$sdfc" merge "$dir/three/shard_00000.exr" "$dir/three/shard_00002.exr" -o "$dir/m.exr"

# A layered merge writes one multi-channel EXR only.
expect 2 "merge: the shards are of a --layers render, .*must end in .exr" \
  -- "$sdfc" merge "$dir/three" -o "$dir/m.png"
[ -e "$dir/m.png" ] && fail "a refused merge wrote $dir/m.png"

# Old and foreign shard formats, and a shard 0 without its layers: edited
# copies (same-length renames keep the EXR valid).
mkdir -p "$dir/old" "$dir/future" "$dir/damaged"
cp "$dir/three/"shard_0000[12].exr "$dir/old/"
cp "$dir/three/"shard_0000[12].exr "$dir/future/"
cp "$dir/three/"shard_0000[12].exr "$dir/damaged/"
/usr/bin/python3 - "$dir/three/shard_00000.exr" "$dir" <<'EOF'
import sys
data = open(sys.argv[1], "rb").read()
def write(name, old, new):
    assert data.count(old) == 1, old
    open(sys.argv[2] + "/" + name + "/shard_00000.exr", "wb").write(data.replace(old, new))
write("old", b"sdfc.format\0", b"sdfc.formax\0")  # as a shard without the attribute
write("future", b"sdfc.format\0string\0\x01\0\0\0" + b"2", b"sdfc.format\0string\0\x01\0\0\0" + b"3")
write("damaged", b"albedo.G\0", b"albedo.Q\0")
EOF
expect 2 "merge: .*old/shard_00000.exr: a shard of an older sdfc \(shard format 1, no 'sdfc.format' attribute\)" \
  -- "$sdfc" merge "$dir/old" -o "$dir/m.exr"
expect 2 "merge: .*future/shard_00000.exr: shard format '3'; this sdfc merges format 2 only" \
  -- "$sdfc" merge "$dir/future" -o "$dir/m.exr"
expect 2 "merge: a --layers shard holding sample 0 of the still has no 'albedo.G' channel" \
  -- "$sdfc" merge "$dir/damaged" -o "$dir/m.exr"
[ -e "$dir/m.exr" ] && fail "a refused merge wrote $dir/m.exr"

if [ "$failures" -ne 0 ]; then
  echo "$failures failure(s)" >&2
  exit 1
fi
echo "all layered farm checks passed"
