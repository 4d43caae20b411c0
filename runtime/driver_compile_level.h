// Lavapipe compiles the kernel with LLVM at its first draw (docs/caches.md);
// for a render of few samples that compile costs more than the optimised
// kernel saves. GALLIVM_PERF=nopt skips LLVM's optimisation passes: the
// compile takes 0.4-0.55x as long, the passes 1.3-1.8x, the image is
// bit-identical (all examples, both drivers; bench/results/fixed_costs.md).
#pragma once
#include <cstdint>

namespace sdfc {

// At most this many samples (pixels x spp x frames) compile unoptimised: the
// castle at 640x360 1 spp still gains (217 ms of compile against 178 of passes).
constexpr uint64_t kQuickCompileMaxSamples = uint64_t(1) << 18;

// Sets GALLIVM_PERF=nopt when `samples` is at most kQuickCompileMaxSamples and
// the user set no GALLIVM_PERF (an empty one keeps LLVM's optimisation); true
// when it did. Call before the first Vulkan call (lavapipe reads it once, when
// its device is enumerated) and before threads that read the environment.
bool chooseQuickDriverCompile(uint64_t samples);

}  // namespace sdfc
