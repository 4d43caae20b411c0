#!/usr/bin/env bash
# Lavapipe from Mesa 25.0.7 (Debian bookworm-backports) beside the system's 22.3.6,
# without touching the system: the packages are downloaded with a private apt
# list of bookworm-backports, unpacked into build/lavapipe-25/, and selected for
# one command through the Vulkan loader's VK_DRIVER_FILES (VK_ICD_FILENAMES for
# older loaders) and LD_LIBRARY_PATH (the driver needs libdrm >= 2.4.121;
# bookworm has 2.4.114).
#
#   tools/lavapipe25.sh fetch              download and unpack (idempotent)
#   tools/lavapipe25.sh run CMD [ARGS...]  run CMD with Mesa 25's lavapipe
#   tools/lavapipe25.sh env                print the exports, for `eval`
#
# Why not install from backports: the system driver stays the one the golden
# images were made with, and a shared machine's other users keep theirs.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
dir="$root/build/lavapipe-25"
version="25.0.7-2~bpo12+1"
packages=("mesa-vulkan-drivers=$version" "libdrm2=2.4.123-1~bpo12+1" "libdrm-amdgpu1=2.4.123-1~bpo12+1")
icd="$dir/lvp_icd.x86_64.json"
libdir="$dir/root/usr/lib/x86_64-linux-gnu"

# The Debian mirror this machine's apt already uses for bookworm (a local
# mirror or proxy stays in use; a bare mmdebstrap root has the host's), else
# deb.debian.org; SDFC_DEBIAN_MIRROR overrides. Backports lives on every full
# Debian mirror.
mirror() {
  [ -n "${SDFC_DEBIAN_MIRROR:-}" ] && { echo "$SDFC_DEBIAN_MIRROR"; return; }
  local uri
  uri=$(cat /etc/apt/sources.list.d/*.sources 2>/dev/null |
        awk '/^URIs:/ { u = $2 } /^Suites:/ && / bookworm( |$)/ && u !~ /security/ { print u; exit }')
  [ -n "$uri" ] || uri=$(cat /etc/apt/sources.list /etc/apt/sources.list.d/*.list 2>/dev/null |
        awk '$1 == "deb" && $3 == "bookworm" { for (i = 2; i <= NF; i++) if ($i ~ /^(https?|file):/) { print $i; exit } }')
  echo "${uri:-http://deb.debian.org/debian}"
}

fetch() {
  [ -f "$icd" ] && return 0
  mkdir -p "$dir/apt/lists/partial" "$dir/apt/cache/archives/partial" "$dir/debs"
  echo "deb [signed-by=/usr/share/keyrings/debian-archive-keyring.gpg] $(mirror) bookworm-backports main" \
    > "$dir/apt/sources.list"
  # A private list and cache; the sandbox user would not be able to write here.
  local apt=(-o "Dir::Etc::SourceList=$dir/apt/sources.list" -o "Dir::Etc::SourceParts=/dev/null"
             -o "Dir::State::Lists=$dir/apt/lists" -o "Dir::Cache=$dir/apt/cache"
             -o "APT::Sandbox::User=root")
  apt-get "${apt[@]}" -qq update
  (cd "$dir/debs" && apt-get "${apt[@]}" -qq download "${packages[@]}")
  for deb in "$dir"/debs/*.deb; do dpkg-deb -x "$deb" "$dir/root"; done
  # Only lavapipe and libdrm are used: drop the GPU drivers and layers (~70 MiB).
  find "$libdir" -maxdepth 1 -type f ! -name 'libvulkan_lvp.so' ! -name 'libdrm*' -delete
  [ -f "$libdir/libvulkan_lvp.so" ] || { echo "lavapipe25: libvulkan_lvp.so missing" >&2; exit 1; }
  cat > "$icd" <<EOF
{
    "ICD": {
        "api_version": "1.4.305",
        "library_path": "$libdir/libvulkan_lvp.so"
    },
    "file_format_version": "1.0.0"
}
EOF
  rm -rf "$dir/apt" "$dir/debs"
  echo "lavapipe25: Mesa $version unpacked into $dir"
}

exports() {
  echo "export VK_DRIVER_FILES='$icd' VK_ICD_FILENAMES='$icd' LD_LIBRARY_PATH='$libdir${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}'"
}

case "${1:-}" in
  fetch) fetch ;;
  env) [ -f "$icd" ] || fetch >&2; exports ;;
  run)
    shift
    [ -f "$icd" ] || fetch >&2
    eval "$(exports)"
    exec "$@" ;;
  *) echo "usage: tools/lavapipe25.sh fetch | env | run CMD [ARGS...]" >&2; exit 2 ;;
esac
