#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan) in their own build
# directory and fuzzes for a bounded time:
#   sdfc_fuzz          the front end (lexer, parser, checker, passes);
#   sdfc_compile_fuzz  check, then emit and glslang on every accepted input
#                      (a checked scene that does not compile is a finding);
#   and one per reader of outside data, each seeded from fuzz/corpus-<kind>:
#   sdfc_mesh_file_fuzz   STL, OBJ, glTF, GLB      (corpus-mesh)
#   sdfc_image_file_fuzz  PNG, .hdr, EXR           (corpus-image)
#   sdfc_point_file_fuzz  CSV point lists          (corpus-points)
#   sdfc_lsp_frame_fuzz   the server's framing     (corpus-lsp)
#   sdfc_import_fuzz      a scene and its imports  (corpus-import: parts cut at NUL bytes)
#   sdfc_lsp_dispatch_fuzz  the server's handling of messages, one body a line
#                                                  (corpus-lsp-dispatch)
#
#   fuzz/run.sh [seconds]          fuzz the scene targets for `seconds` in all
#                                  (default 60: a third on sdfc_fuzz, the rest on
#                                  sdfc_compile_fuzz), then each reader for a third
#                                  of it: 30 takes 90 s of fuzzing
#   fuzz/run.sh --replay [files]   run .sdf inputs once through both scene targets
#                                  (default: fuzz/regressions/*.sdf), and each
#                                  reader's seeds (its regressions among them) once
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
readers="mesh_file:mesh image_file:image point_file:points lsp_frame:lsp import:import lsp_dispatch:lsp-dispatch"
reader_targets=()
for r in $readers; do reader_targets+=("sdfc_${r%%:*}_fuzz"); done
ninja -C "$build" -j "$jobs" sdfc_fuzz sdfc_compile_fuzz "${reader_targets[@]}" >"$log" 2>&1 ||
  { cat "$log" >&2; exit 2; }
front=$build/fuzz/sdfc_fuzz
back=$build/fuzz/sdfc_compile_fuzz

if [ "${1:-}" = "--replay" ]; then
  shift
  if [ $# -eq 0 ]; then
    set -- "$root"/fuzz/regressions/*.sdf
    # Every seed without the tinyexr suppression but the one input that needs it
    # (fuzz/lsan.supp), so that a leak of sdfc's own is still caught here.
    for r in $readers; do
      seeds=()
      for f in "$root/fuzz/corpus-${r#*:}"/*; do [[ $f == *tinyexr_leak* ]] || seeds+=("$f"); done
      "$build/fuzz/sdfc_${r%%:*}_fuzz" "${seeds[@]}"
    done
    LSAN_OPTIONS=suppressions=$root/fuzz/lsan.supp "$build/fuzz/sdfc_image_file_fuzz" "$root"/fuzz/corpus-image/*tinyexr_leak*
  fi
  "$front" "$@"
  "$back" "$@"
  exit
fi

seconds=${1:-60}
front_seconds=$(( seconds / 3 > 0 ? seconds / 3 : 1 ))
back_seconds=$(( seconds - front_seconds > 0 ? seconds - front_seconds : 1 ))
mkdir -p "$build/corpus" "$build/corpus-compile" "$build/artifacts"
# New inputs go to the first directory (in the build tree); fuzz/corpus,
# fuzz/regressions and examples/ are read-only seeds. The compile target
# also starts from what the front-end runs found.
status=0
"$front" "$build/corpus" "$root/fuzz/corpus" "$root/examples" \
  -dict="$root/fuzz/sdf.dict" -max_total_time="$front_seconds" -max_len=4096 -timeout=10 \
  -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$build/artifacts/front-" || status=$?
"$back" "$build/corpus-compile" "$root/fuzz/corpus" "$root/fuzz/regressions" "$root/examples" \
  "$build/corpus" -dict="$root/fuzz/sdf.dict" -max_total_time="$back_seconds" -max_len=4096 \
  -timeout=30 -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$build/artifacts/compile-" ||
  status=$?
# The readers: a third of `seconds` each, from their seeds (new inputs in the
# build tree), small inputs (the formats' corners fit in a few kilobytes).
reader_seconds=$(( seconds / 3 > 0 ? seconds / 3 : 1 ))
for r in $readers; do
  target=sdfc_${r%%:*}_fuzz kind=${r#*:}
  mkdir -p "$build/corpus-$kind"
  # Words of the input's language: the scene language's for imports, JSON-RPC's for dispatch.
  dict=()
  case $kind in
    import) dict=(-dict="$root/fuzz/sdf.dict") ;;
    lsp-dispatch) dict=(-dict="$root/fuzz/lsp-dispatch.dict") ;;
  esac
  # tinyexr's own leaks on bad pixel blocks (fuzz/lsan.supp) would end every image run.
  LSAN_OPTIONS=suppressions=$root/fuzz/lsan.supp \
  "$build/fuzz/$target" "$build/corpus-$kind" "$root/fuzz/corpus-$kind" "${dict[@]}" -max_total_time="$reader_seconds" \
    -max_len=16384 -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
    -artifact_prefix="$build/artifacts/$kind-" || status=$?
done
exit $status
