#!/usr/bin/env bash
# The fresh-machine check: runs the README's two quick-start commands, verbatim,
# in a bare Debian 12 root that has nothing installed beyond minbase, because
# this machine (and CI's) already has packages a user's lacks and a green CI
# here once hid a missing install step.
#
#   tools/fresh_machine_check.sh [--keep] [--copy-in PATH]... [--then CMD]...
#
# --then CMD runs one more command in the same root after the README's two
# (CI runs its other suites there, on the build the quick start made, instead
# of building again on this machine); --copy-in PATH copies a file or folder of
# this machine into the root first, at the same path (CI's Node.js 20, which
# Debian 12 lacks, for the VS Code extension). Neither touches the quick start.
#
# Builds the root with mmdebstrap (cached as a tarball in $SDFC_FRESH_CACHE; the
# bare root only, never its installed packages), copies a clean clone of HEAD
# into it, and runs each command in a chroot inside private mount and PID
# namespaces (so mounts and stray processes die with it). Prints each
# command's wall time; fails on the first command that fails. Needs root.
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$(pwd)

keep=0
copy_in=()
then_commands=()
while [ $# -gt 0 ]; do
  case "$1" in
    --keep) keep=1 ;;
    --copy-in) copy_in+=("${2:?--copy-in needs a path}"); shift ;;
    --then) then_commands+=("${2:?--then needs a command}"); shift ;;
    *) echo "fresh_machine_check: unknown option '$1'" >&2; exit 2 ;;
  esac
  shift
done
if [ "$(id -u)" -ne 0 ]; then
  echo "fresh_machine_check: needs root (it builds a Debian root and chroots into it)" >&2
  exit 2
fi

cache=${SDFC_FRESH_CACHE:-/var/cache/sdfc}
suite=bookworm
tarball="$cache/fresh-root-$suite-minbase.tar"

# The commands, read from the README's quick start (its first code block) so
# the two cannot drift.
mapfile -t commands < <(awk '
  /^## Quick start/ { in_section = 1; next }
  in_section && /^## / { exit }
  in_section && /^```/ { if (in_block) exit; in_block = 1; next }
  in_section && in_block && NF { sub(/[ \t]*#.*/, ""); print }
' README.md)
if [ ${#commands[@]} -ne 2 ]; then
  echo "fresh_machine_check: expected 2 commands in README's quick start, found ${#commands[@]}" >&2
  exit 1
fi

need_host_tool() {
  command -v "$1" >/dev/null && return
  echo "fresh_machine_check: installing $2 on this machine (to build the bare root)"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "$2" >/dev/null
}
need_host_tool mmdebstrap mmdebstrap
need_host_tool git git

if [ ! -s "$tarball" ]; then
  mkdir -p "$cache"
  # The host's apt sources (the same mirror and security suite a user gets).
  sources=/etc/apt/sources.list.d/debian.sources
  [ -f "$sources" ] || sources=/etc/apt/sources.list
  echo "fresh_machine_check: building a bare Debian 12 root ($tarball)"
  # --format: the temporary name ends in .part, which mmdebstrap would take for a directory.
  mmdebstrap --quiet --variant=minbase --format=tar "$suite" "$tarball.part" "$sources"
  mv "$tarball.part" "$tarball"
fi

root=$(mktemp -d /var/tmp/sdfc-fresh-root.XXXXXX)
cleanup() {
  if [ "$keep" -eq 1 ]; then
    echo "fresh_machine_check: root kept at $root"
  else
    rm -rf --one-file-system "$root"
  fi
}
trap cleanup EXIT

tar -C "$root" -xf "$tarball"
cp /etc/resolv.conf "$root/etc/resolv.conf" 2>/dev/null || true
# A clean clone of what is committed, as a user would have it.
git clone --quiet --no-hardlinks "$repo" "$root/root/sdfc"

run_in_root() {
  local cmd=$1 start rc wall
  echo "fresh_machine_check: \$ $cmd"
  start=$(date +%s.%N)
  set +e
  unshare --mount --pid --fork --kill-child env -i \
    HOME=/root PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    TERM=dumb LANG=C.UTF-8 ROOT="$root" CMD="$cmd" bash -c '
      set -e
      mount --make-rprivate /
      mount -t proc proc "$ROOT/proc"
      mount --rbind /dev "$ROOT/dev"
      # /sys with its cgroup mount, as a booted machine has it (slurmd needs it)
      mount --rbind /sys "$ROOT/sys"
      mount -t tmpfs tmpfs "$ROOT/dev/shm"
      mount -t tmpfs tmpfs "$ROOT/run"
      exec chroot "$ROOT" bash -c "cd /root/sdfc && $CMD"
    ' 2>&1 | sed -u 's/^/  | /'
  rc=${PIPESTATUS[0]}
  set -e
  wall=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { print b - a }')
  printf 'fresh_machine_check: "%s" exited %d after %.0f s\n' "$cmd" "$rc" "$wall"
  return "$rc"
}

status=0
for cmd in "${commands[@]}"; do
  run_in_root "$cmd" || { status=1; break; }
done

if [ "$status" -eq 0 ]; then
  echo "fresh_machine_check: passed: the README's commands work on a bare Debian 12 root"
  for path in "${copy_in[@]}"; do
    # into the same folder of the root, over what the quick start installed
    mkdir -p "$root$(dirname "$path")"
    cp -a "$path" "$root$(dirname "$path")/"
  done
  for cmd in "${then_commands[@]}"; do
    run_in_root "$cmd" || { status=1; break; }
  done
  [ "$status" -eq 0 ] || echo "fresh_machine_check: FAILED (a --then command)" >&2
else
  echo "fresh_machine_check: FAILED" >&2
fi
exit "$status"
