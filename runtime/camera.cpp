#include "camera.h"

#include <cmath>

namespace sdfc {

gpu::FrameParams makeFrameParams(const CameraDesc& camera, uint32_t width, uint32_t height,
                                 float time) {
  glm::vec3 offset = camera.target - camera.position;
  float distance = glm::length(offset);
  glm::vec3 forward = distance > 1e-20f ? offset / distance : glm::vec3(0, 0, -1);
  if (!(distance > 1e-20f)) distance = 1.0f;
  glm::vec3 up = camera.up;
  glm::vec3 right = glm::cross(forward, up);
  if (glm::length(right) < 1e-6f * std::fmax(glm::length(up), 1e-30f)) {
    // Looking along `up`: any perpendicular axis keeps the basis valid.
    up = std::fabs(forward.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(0, 0, 1);
    right = glm::cross(forward, up);
  }
  right = glm::normalize(right);
  up = glm::cross(right, forward);

  const float tan_half_fov = std::tan(glm::radians(camera.fov_degrees) * 0.5f);
  const float focus = camera.focus_distance > 0 ? camera.focus_distance : distance;

  gpu::FrameParams params{};
  params.cam_origin = glm::vec4(camera.position, tan_half_fov);
  params.cam_right = glm::vec4(right, camera.aperture);
  params.cam_up = glm::vec4(up, focus);
  params.cam_forward = glm::vec4(forward, time);
  params.width = width;
  params.height = height;
  params.sample_base = 0;
  params.sample_count = 1;
  params.seed = 0;
  params.view = gpu::kViewBeauty;
  params.max_bounces = 3;
  params.light_samples = 1;
  return params;
}

}  // namespace sdfc
