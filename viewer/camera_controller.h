// Mouse and keys -> camera, as in common 3D tools: left drag orbits around the
// target, middle (or shift+left) drag pans, the wheel zooms towards the target,
// right drag dollies eye and target together. Every change bumps generation(), which
// the view loop compares to restart the accumulation.
#pragma once
#include <glm/glm.hpp>

#include <cstdint>
#include <string>

#include "camera.h"

namespace sdfc::view {

class CameraController {
 public:
  void reset(const CameraDesc& camera);
  const CameraDesc& camera() const { return camera_; }
  uint64_t generation() const { return generation_; }

  // Degrees about the world up axis (yaw) and the camera's right axis (pitch,
  // kept within 89 degrees of the horizon).
  void orbit(float yaw_degrees, float pitch_degrees);
  // Moves eye and target by a screen-space offset in pixels of a view `height` tall.
  void pan(float dx_pixels, float dy_pixels, uint32_t height);
  // Eye distance to the target times `factor` (< 1 closer).
  void zoom(float factor);
  // Eye and target forward by `amount` times the eye distance.
  void dolly(float amount);
  // Looks at the box [lo, hi] from the current direction, the whole box in view.
  void frame(const glm::dvec3& lo, const glm::dvec3& hi, float aspect);

  // Mouse events in window pixels; `height` is the view height (pan scale).
  void mouseButton(int button, bool down, bool shift);
  void cursor(double x, double y, uint32_t height);
  void scroll(double dy);
  bool dragging() const { return buttons_ != 0; }

  // `camera(position: [...], target: [...], fov: ...)`, ready to paste into a .sdf:
  // in world coordinates, the camera being in the scene's frame at `origin`.
  std::string cameraLine(const glm::dvec3& origin = glm::dvec3(0)) const;
  // Eye and target by `by`: the same view in a scene frame moved by -by.
  void translate(const glm::dvec3& by);

 private:
  void changed() { ++generation_; }

  CameraDesc camera_;
  uint64_t generation_ = 0;
  int buttons_ = 0;  // bit 0 left, 1 right, 2 middle
  bool shift_ = false;
  bool have_cursor_ = false;
  double last_x_ = 0, last_y_ = 0;
};

}  // namespace sdfc::view
