#!/usr/bin/env bash
# Issue 36: a render of few samples has lavapipe compile its kernel without
# LLVM's optimisation passes (runtime/driver_compile_level.h), says so in
# --timings, leaves a user's GALLIVM_PERF alone, and writes the same floats as
# the optimised kernel. Usage: quick_compile_test.sh <sdfc>
set -uo pipefail
sdfc=$1
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/sdfc quick compile.XXXXXX")  # a space in every path
trap 'rm -rf "$work"' EXIT
failures=0
export XDG_CACHE_HOME="$work/cache" SDFC_VALIDATION=1
unset GALLIVM_PERF

. "$root/tests/cli_expect.sh"

sphere=$root/examples/diffuse_sphere.sdf
expect 0 "first draw.*LLVM unoptimised" -- "$sdfc" render "$sphere" -o "$work/a.png" --size 32x18 --spp 2 --timings -q
expect 0 "" -- env GALLIVM_PERF= "$sdfc" render "$sphere" -o "$work/a.png" --size 32x18 --spp 2 --timings -q
grep -q "unoptimised" "$work/err" && fail "a user's GALLIVM_PERF (empty) was overridden"
# The limit, 2^18 samples: a 512x512 debug view is one sample a pixel.
expect 0 "unoptimised" -- "$sdfc" render "$sphere" -o "$work/a.png" --size 512x512 --view normal --timings -q
expect 0 "" -- "$sdfc" render "$sphere" -o "$work/a.png" --size 513x512 --view normal --timings -q
grep -q "unoptimised" "$work/err" && fail "2^18 + 512 samples compiled unoptimised"

# An image nothing denoises gets the kernel without features (kernel_features_test.cpp
# checks its colour and steps); a denoised one the full kernel.
expect 0 "emit GLSL.*no AOV features" -- "$sdfc" render "$sphere" -o "$work/a.png" --size 32x18 --spp 2 --denoise none --timings -q
expect 0 "" -- "$sdfc" render "$sphere" -o "$work/a.png" --size 32x18 --spp 2 --timings -q
grep -q "no AOV features" "$work/err" && fail "a denoised render got the kernel without features"

# Unoptimised and optimised kernels write the same floats (EXR: no rounding).
for scene in castle glass_and_metal; do
  expect 0 "unoptimised" -- "$sdfc" render "$root/examples/$scene.sdf" -o "$work/quick.exr" --size 32x18 --spp 2 --denoise none --timings -q
  expect 0 "" -- env GALLIVM_PERF= "$sdfc" render "$root/examples/$scene.sdf" -o "$work/full.exr" --size 32x18 --spp 2 --denoise none -q
  cmp -s "$work/quick.exr" "$work/full.exr" || fail "$scene: the unoptimised kernel's image differs"
done

[ "$failures" -eq 0 ] && echo "all passed" || { echo "$failures failed" >&2; exit 1; }
