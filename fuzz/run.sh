#!/usr/bin/env bash
# Builds the libFuzzer target with clang (ASan + UBSan) in its own build
# directory and fuzzes the front end for a bounded time.
#
#   fuzz/run.sh [seconds]          fuzz for `seconds` (default 60)
#   fuzz/run.sh --replay [files]   run inputs once (default: fuzz/regressions/*)
#
# Environment: SDFC_FUZZ_BUILD (build dir, default build-fuzz next to fuzz/),
# SDFC_FUZZ_JOBS (ninja jobs). Exits non-zero when the fuzzer finds a crash,
# leak, sanitizer report or hang; the input is written to
# $SDFC_FUZZ_BUILD/artifacts/.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
build=${SDFC_FUZZ_BUILD:-$root/build-fuzz}
jobs=${SDFC_FUZZ_JOBS:-$(nproc)}

command -v clang++ >/dev/null || { echo "fuzz/run.sh: clang++ not found (apt-get install clang)" >&2; exit 2; }

# Until the top-level CMakeLists.txt adds fuzz/ itself, attach it from outside.
hook=()
grep -q '^[[:space:]]*add_subdirectory(fuzz)' "$root/CMakeLists.txt" ||
  hook=(-DCMAKE_PROJECT_INCLUDE="$root/fuzz/attach.cmake")

# -O1 with line tables: quick to build, fast enough to fuzz, readable stacks.
log=$(mktemp)
trap 'rm -f "$log"' EXIT
if [ ! -f "$build/build.ninja" ]; then
  CC=clang CXX=clang++ cmake -S "$root" -B "$build" -G Ninja -DSDFC_FUZZ=ON \
    -DCMAKE_BUILD_TYPE=Fuzz -DCMAKE_CXX_FLAGS_FUZZ="-O1 -gline-tables-only" \
    -DCMAKE_C_FLAGS_FUZZ="-O1" "${hook[@]}" >"$log" 2>&1 || { cat "$log" >&2; exit 2; }
fi
ninja -C "$build" -j "$jobs" sdfc_fuzz >"$log" 2>&1 || { cat "$log" >&2; exit 2; }
fuzzer=$build/fuzz/sdfc_fuzz

if [ "${1:-}" = "--replay" ]; then
  shift
  if [ $# -eq 0 ]; then set -- "$root"/fuzz/regressions/*.sdf; fi
  "$fuzzer" "$@"
  exit
fi

seconds=${1:-60}
mkdir -p "$build/corpus" "$build/artifacts"
# New inputs go to the first directory (in the build tree); fuzz/corpus and
# examples/ are read-only seeds.
"$fuzzer" "$build/corpus" "$root/fuzz/corpus" "$root/examples" \
  -dict="$root/fuzz/sdf.dict" -max_total_time="$seconds" -max_len=4096 -timeout=10 \
  -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$build/artifacts/"
