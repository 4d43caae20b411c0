// Worst-case loop iterations of the path-tracing kernel
// (compiler/emit/kernel/pathtrace.glsl), so a pass never reaches lavapipe's cap.
//
// Lavapipe counts loop iterations per invocation in total and runs 8 lanes in
// lockstep: a loop runs as long as any lane needs it. The bound is therefore
// structural: every loop site counted with its trip-count limit, once per
// iteration of the loops enclosing it, whatever branch the lanes took. One sample
// (one iteration of main's sample loop) runs:
//   1                                  sample loop
//   + (B + 1 + B * L) * (1 + S + 2 N + 5)
//                                      path loop: one march a ray (the path's
//                                      B + 1 rays and L shadow rays at each of
//                                      the B vertices that may scatter), the
//                                      sphere-light test, the normal's 4 taps and
//                                      the material (5; march() runs them in its
//                                      loop after the hit, which is then at most
//                                      S + 5 long: a march that ends without
//                                      taps takes at most S + 1, its last
//                                      iteration only closing it), and the
//                                      light sample's sphere-light occlusion test
// with S = kSceneMaxSteps + kRefineSteps (a march may add kRefineSteps
// iterations after a hit to refine it), B = max_bounces, L = light_samples,
// N = sphere lights.
// Each pass also traces one unjittered primary ray for the AOVs (sample loop
// iteration s = -1, B = 0): 1 + (1 + S + 2 N + 5).
#pragma once
#include <cstdint>

#include "shader_interface.h"

namespace sdfc {

// The kernel refuses to compile scenes with more sphere lights (a negative array
// size), so this default is a true bound for every scene.
constexpr uint32_t kMaxSphereLights = 16;

// Iterations a march may add after its hit (kRefineSteps in pathtrace.glsl).
constexpr uint64_t kRefineSteps = 2;

// The normal's evaluations in a shading kernel (march()'s loop after a hit): 4 taps and the material id.
constexpr uint64_t kNormalLoopIterations = 5;

constexpr uint64_t loopIterationsPerSampleWide(uint64_t max_steps, uint64_t max_bounces,
                                               uint64_t light_samples, uint64_t sphere_lights) {
  const uint64_t march = max_steps + kRefineSteps;
  return 1 + (max_bounces + 1 + max_bounces * light_samples) * (1 + march + 2 * sphere_lights + kNormalLoopIterations);
}

// Upper bound on the loop iterations of one sample. Pass the scene's number of
// sphere lights when known; the default assumes the most the kernel accepts.
constexpr uint32_t loopIterationsPerSample(uint32_t max_steps, uint32_t max_bounces,
                                           uint32_t light_samples,
                                           uint32_t sphere_lights = kMaxSphereLights) {
  const uint64_t n = loopIterationsPerSampleWide(max_steps, max_bounces, light_samples, sphere_lights);
  return n > UINT32_MAX ? UINT32_MAX : uint32_t(n);
}

// Loop iterations of a pass independent of its sample count (the AOV ray).
constexpr uint32_t loopIterationsPerPassOverhead(uint32_t max_steps,
                                                 uint32_t sphere_lights = kMaxSphereLights) {
  return 1 + (1 + max_steps + uint32_t(kRefineSteps) + 2 * sphere_lights + uint32_t(kNormalLoopIterations));
}

// Upper bound on the loop iterations of a pass of `sample_count` samples.
constexpr uint64_t loopIterationsPerPass(uint32_t max_steps, uint32_t max_bounces,
                                         uint32_t light_samples, uint32_t sample_count,
                                         uint32_t sphere_lights = kMaxSphereLights) {
  return loopIterationsPerPassOverhead(max_steps, sphere_lights) +
         uint64_t(sample_count) *
             loopIterationsPerSampleWide(max_steps, max_bounces, light_samples, sphere_lights);
}

// The largest sample_count whose pass stays strictly below kLavapipeLoopCap;
// 0 if not even one sample fits (the scene's step or bounce budget is too big).
constexpr uint32_t samplesPerPassWithinCap(uint32_t max_steps, uint32_t max_bounces,
                                           uint32_t light_samples,
                                           uint32_t sphere_lights = kMaxSphereLights) {
  const uint64_t overhead = loopIterationsPerPassOverhead(max_steps, sphere_lights);
  const uint64_t per_sample =
      loopIterationsPerSampleWide(max_steps, max_bounces, light_samples, sphere_lights);
  if (overhead + per_sample >= gpu::kLavapipeLoopCap) return 0;
  return uint32_t((gpu::kLavapipeLoopCap - 1 - overhead) / per_sample);
}

// Instance hierarchies (compiler/emit: one loop per evaluation of an Instances
// node, at most frame.traversal_visits iterations). Every scene evaluation in
// the kernel sits in the body of a counted loop iteration, one per iteration
// (march step, normal tap or material id), except the
// inside test each tracePath call makes before its path loop: so a pass makes
// at most (its loop iterations + samples + 1) evaluations (+ 1: the AOV ray).
// An evaluation (sdScene or sdSceneMaterial) reaches at most
// `sets_per_evaluation` Instances nodes.
constexpr uint64_t sceneEvaluationsPerPass(uint64_t kernel_iterations, uint32_t sample_count) {
  return kernel_iterations + sample_count + 1;
}

// The most hierarchy visits per evaluation that keep a pass whose kernel loops
// take `kernel_iterations` strictly below the cap (0: none fit).
constexpr uint32_t traversalVisitsWithinCap(uint64_t kernel_iterations, uint32_t sample_count,
                                            uint32_t sets_per_evaluation = 1) {
  if (kernel_iterations + 1 >= gpu::kLavapipeLoopCap || sets_per_evaluation == 0) return 0;
  const uint64_t evaluations =
      sceneEvaluationsPerPass(kernel_iterations, sample_count) * sets_per_evaluation;
  return uint32_t((gpu::kLavapipeLoopCap - 1 - kernel_iterations) / evaluations);
}

static_assert(traversalVisitsWithinCap(1000, 1) == (65535 - 1 - 1000) / 1002);

static_assert(loopIterationsPerSample(98, 0, 0, 0) == 1 + 106);
static_assert(loopIterationsPerPass(98, 2, 1, 3, 0) == 107 + 3 * (1 + 5 * 106));
static_assert(loopIterationsPerSample(98, 2, 1, 2) == 1 + 5 * 110);
static_assert(loopIterationsPerPass(256, 4, 1, samplesPerPassWithinCap(256, 4, 1)) <
              gpu::kLavapipeLoopCap);
static_assert(loopIterationsPerPass(256, 4, 1, samplesPerPassWithinCap(256, 4, 1) + 1) >=
              gpu::kLavapipeLoopCap);

}  // namespace sdfc
