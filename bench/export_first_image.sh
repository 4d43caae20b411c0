#!/usr/bin/env bash
# Time to the first image of an exported page in headless Chromium (SwiftShader's
# WebGL2), issue 34's target: under 2 s for the castle. Alternates the half-size
# first image (what a user gets) with a full-size one, RUNS times each, and prints
# every run and the medians of the page's own clock (navigation start -> the first
# image's pixels read back).
#   bench/export_first_image.sh [scene.sdf] [RUNS]
set -euo pipefail
cd "$(dirname "$0")/.."
scene=${1:-examples/castle.sdf}
runs=${2:-5}
sdfc=${SDFC:-build/cli/sdfc}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$sdfc" export "$scene" -o "$tmp/page.html" -q
browser() {
  chromium --headless --no-sandbox --no-first-run --user-data-dir="$tmp/profile" --use-gl=angle \
    --use-angle=swiftshader --enable-unsafe-swiftshader --dump-dom "file://$tmp/page.html#test&views=beauty&spp=1$1" \
    2>/dev/null | grep -o '"first_image_ms":[0-9.]*' | cut -d: -f2
}
half=() full=()
for ((i = 0; i < runs; ++i)); do
  half+=("$(browser '&preview')")
  full+=("$(browser '')")
  echo "run $i: half-size first image ${half[-1]} ms, full size ${full[-1]} ms (load $(cut -d' ' -f1 /proc/loadavg))"
done
median() { printf '%s\n' "$@" | sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
echo "median: half-size $(median "${half[@]}") ms, full size $(median "${full[@]}") ms; page $(stat -c %s "$tmp/page.html") bytes"
