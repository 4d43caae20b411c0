#include "camera_inside.h"

#include <algorithm>
#include <cmath>

#include "eval/evaluator.h"

namespace sdfc {

bool cameraInside(const ir::Scene& scene, const MarchLimits& limits, const glm::vec3& origin,
                  float time) {
  const float d = float(Evaluator(scene, time).distance(glm::dvec3(origin)));
  // pathtrace.glsl's kFpUlps and fpEps(ro_mag, 0), in float as the kernel computes them.
  const float fp_ulps = 8.0f * 1.1920929e-7f;
  const float ro_mag = std::max({std::fabs(origin.x), std::fabs(origin.y), std::fabs(origin.z)});
  const float eps = float(limits.hit_epsilon) + fp_ulps * ro_mag;
  return d < -eps;
}

CameraInsideTest cameraInsideTest(const ir::Scene& scene, const MarchLimits& limits) {
  return [&scene, limits](const glm::vec3& origin, float time) {
    return cameraInside(scene, limits, origin, time);
  };
}

}  // namespace sdfc
