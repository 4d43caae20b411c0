#!/usr/bin/env bash
# Regenerates the golden GLSL (examples/*.expected.glsl) and the reference
# images (tests/golden_images/*.exr) after an intended change. Review the diff.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --build build --target sdfc_tests
SDFC_UPDATE_GOLDENS=1 ./build/tests/sdfc_tests --gtest_filter='Golden*'
git status --short examples tests/golden_images
