#!/bin/sh
# `sdfc render --shards` on a scene whose spheres are instances (scene data in a
# storage buffer): every shard renders, validation on, and the merged image is
# the single render's, byte for byte. (The shard command once built its renderer
# without the scene data: a validation error and no shard file.)
# Usage: tests/shard_instances_test.sh path/to/sdfc
set -eu
sdfc=$1
dir=$(mktemp -d "${TMPDIR:-/tmp}/sdfc_shard_instances.XXXXXX")
trap 'rm -rf "$dir"' EXIT
scene=$dir/spheres.sdf
{
  echo 'camera(position: [0, 3, -12], target: [0, 0, 0])'
  echo 'sun(direction: [1, 2, -1])'
  echo 'scene { union {'
  i=0
  while [ $i -lt 64 ]; do
    echo "  translate([$((i % 8 - 4)), $((i % 3)) * 0.5, $((i / 8 - 4))]) { sphere(0.3) }"
    i=$((i + 1))
  done
  echo '} }'
} > "$scene"
"$sdfc" compile "$scene" --emit ir | grep -q 'data form' ||
  { echo "FAIL: the spheres did not become instance data"; exit 1; }
export SDFC_VALIDATION=1
for i in 0 1; do
  status=0
  "$sdfc" render "$scene" --size 48x27 --spp 2 --shards 2 --shard-index $i -o "$dir/shards" --quiet \
    2>"$dir/err$i" || status=$?
  if [ $status -ne 0 ] || [ -s "$dir/err$i" ]; then
    echo "FAIL: shard $i exited $status and printed:"; cat "$dir/err$i"; exit 1
  fi
done
"$sdfc" merge "$dir/shards" -o "$dir/merged.pfm" --quiet
"$sdfc" render "$scene" --size 48x27 --spp 2 --denoise none -o "$dir/single.pfm" --quiet
cmp "$dir/merged.pfm" "$dir/single.pfm" || { echo "FAIL: merged shards differ from the single render"; exit 1; }
echo "ok: 2 shards of a 64-instance scene merge to the single render"
