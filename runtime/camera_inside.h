// Whether a pinhole camera sits inside a solid: one value per frame (and time)
// instead of an inlined copy of the scene in every pixel's kernel.
#pragma once
#include <functional>

#include <glm/glm.hpp>

#include "emit/glsl_emitter.h"
#include "ir/scene.h"

namespace sdfc {

// (camera origin, scene time) -> inside. Empty: the camera is taken as outside.
using CameraInsideTest = std::function<bool(const glm::vec3&, float)>;

// The kernel's test `sdScene(ro) < -fpEps(maxComponent(abs(ro)), 0)` on the CPU:
// the float64 evaluator's distance rounded to float against the same float
// threshold (kSceneHitEps + 8 ulp(1) * max |ro_i|). `scene` must outlive the result.
bool cameraInside(const ir::Scene& scene, const MarchLimits& limits, const glm::vec3& origin,
                  float time);
CameraInsideTest cameraInsideTest(const ir::Scene& scene, const MarchLimits& limits);

}  // namespace sdfc
