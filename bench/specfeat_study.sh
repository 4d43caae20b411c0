#!/bin/sh
# Features through specular bounces (docs/denoise.md): nlr with plain jittered
# features against nlr through specular first hits, with and without --adaptive,
# castle / colonnade / glass Menger at 640x360 16 spp, seeds 7 and 8 (errors are
# deterministic per seed), then the render time of the two, 3 interleaved runs.
# About 6 min on an idle machine. Writes bench/results/ADAPTIVE_640x360_specfeat_*.md.
#   sh bench/specfeat_study.sh [path/to/sdfc]
set -e
cd "$(dirname "$0")/.."
SDFC=${1:-build/cli/sdfc}
for seed in 7 8; do
  /usr/bin/python3 bench/adaptive_study.py --sdfc "$SDFC" --mesa25 --reuse-refs --seed $seed \
    --tag specfeat_s$seed --configs nlr/jittered nlr/specular nlr/jittered+a nlr/specular+a
done
/usr/bin/python3 bench/adaptive_study.py --sdfc "$SDFC" --mesa25 --reuse-refs --seed 7 --reps 3 \
  --tag specfeat_time --scenes examples/glass_menger.sdf examples/castle.sdf \
  --configs nlr/jittered nlr/specular
