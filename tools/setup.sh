#!/usr/bin/env bash
# Installs what sdfc needs from Debian 12 (skipped when already present) and
# builds it into ./build. Safe to run again.
#
#   tools/setup.sh [TARGET...]   build only these CMake targets (castle.sh: sdfc);
#                                everything when none is named
#
# Every package is listed explicitly and installed with --no-install-recommends,
# so this list is the whole truth: tools/fresh_machine_check.sh proves it on a
# bare Debian root.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  # build
  cmake ninja-build g++ pkg-config
  # GLSL -> SPIR-V as a library; glslang-dev's CMake config also imports
  # /usr/bin/glslangValidator from glslang-tools
  glslang-dev glslang-tools spirv-tools
  # Vulkan, lavapipe (the CPU device), validation layers for the tests
  libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers
  # libraries
  libglm-dev libtinygltf-dev nlohmann-json3-dev libstb-dev libtinyexr-dev libcli11-dev zlib1g-dev
  # tests, benchmark smoke run, fuzzing
  libgtest-dev python3-numpy python3-matplotlib clang
  # the Python package (python/): its bindings and its tests
  pybind11-dev python3-dev python3-pytest python3-venv
  # libFuzzer's and the sanitizers' runtimes (clang alone does not bring them)
  libclang-rt-14-dev
  # the render farm's tests: a single-node Slurm cluster
  slurmctld slurmd slurm-client munge
  # the language server's test in a real client
  neovim
  # sdfc view: the window (GLFW), and its tests under Xvfb with an X screenshot (xwd)
  # and a real key press (XTEST, tests/view_quit_test.py)
  libglfw3-dev xvfb xauth x11-apps libxtst6
  # sdfc export's tests: the exported page in headless Chromium (SwiftShader's WebGL2)
  chromium
)

say() { echo "setup: $*"; }
fail() {
  echo "setup: error: $*" >&2
  exit 1
}

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -gt 0 ]; then
  say "${#missing[@]} Debian package(s) missing: ${missing[*]}"
  as_root=()
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null ||
      fail "installing packages needs root, and sudo is not installed; as root run:
  apt-get update && apt-get install --no-install-recommends ${missing[*]}
then run this command again"
    say "installing them needs root: running apt-get through sudo"
    as_root=(sudo)
  fi
  say "apt-get update"
  "${as_root[@]}" apt-get -o DPkg::Lock::Timeout=300 update -qq ||
    fail "apt-get update failed (network or apt sources?); nothing was installed"
  say "apt-get install (this takes a few minutes on a new machine)"
  log=$(mktemp)
  if ! DEBIAN_FRONTEND=noninteractive "${as_root[@]}" apt-get -o DPkg::Lock::Timeout=300 install -y -qq \
      --no-install-recommends "${missing[@]}" > "$log" 2>&1; then
    tail -n 20 "$log" >&2
    rm -f "$log"
    fail "apt-get could not install: ${missing[*]} (see apt's message above)"
  fi
  rm -f "$log"
  for p in "${missing[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" ||
      fail "package $p is still not installed after apt-get install"
  done
  say "packages installed"
fi

# Mesa 25.0.7's lavapipe from bookworm-backports, unpacked into build/lavapipe-25
# (no system package changes); sdfc uses it by default when it is there
# (docs/lavapipe.md). Without network or on failure: the system's 22.3.6.
if [ "${SDFC_BUNDLED_DRIVER:-1}" != 0 ]; then
  tools/lavapipe25.sh fetch ||
    say "warning: could not fetch Mesa 25's lavapipe; sdfc will use the system driver"
fi

say "configuring and building into build/"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo > /dev/null
if [ $# -gt 0 ]; then
  cmake --build build --target "$@"
else
  cmake --build build
fi
