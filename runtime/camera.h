// Pinhole / thin-lens camera description and its packing into FrameParams.
#pragma once
#include <glm/glm.hpp>

#include <cstdint>

#include "shader_interface.h"

namespace sdfc {

struct CameraDesc {
  glm::vec3 position{0, 0, 5}, target{0, 0, 0}, up{0, 1, 0};
  float fov_degrees = 45;     // vertical field of view
  float aperture = 0;         // lens radius; 0 = pinhole
  float focus_distance = 0;   // 0 = distance from position to target
};

// Fills the camera fields (right-handed orthonormal basis: right = forward x up),
// width/height and time. An `up` parallel to the view direction is replaced by
// another axis. Sampling fields are left at zero/defaults (view = beauty,
// max_bounces = 3, light_samples = 1) for the renderer to set.
gpu::FrameParams makeFrameParams(const CameraDesc& camera, uint32_t width, uint32_t height,
                                 float time);

}  // namespace sdfc
