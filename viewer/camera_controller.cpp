#include "camera_controller.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace sdfc::view {
namespace {

constexpr float kOrbitDegreesPerPixel = 0.25f;
constexpr float kZoomPerWheelStep = 0.9f;
constexpr float kDollyPerPixel = 0.005f;
constexpr float kMaxPitch = 89.0f;

}  // namespace

void CameraController::reset(const CameraDesc& camera) {
  camera_ = camera;
  changed();
}

void CameraController::orbit(float yaw_degrees, float pitch_degrees) {
  const glm::vec3 up = glm::length(camera_.up) > 0 ? glm::normalize(camera_.up) : glm::vec3(0, 1, 0);
  glm::vec3 offset = camera_.position - camera_.target;
  const float distance = glm::length(offset);
  if (!(distance > 0)) return;
  glm::vec3 dir = offset / distance;
  // Pitch: angle above the horizon plane, clamped away from the poles.
  const float elevation = glm::degrees(std::asin(std::clamp(glm::dot(dir, up), -1.0f, 1.0f)));
  const float new_elevation = std::clamp(elevation + pitch_degrees, -kMaxPitch, kMaxPitch);
  glm::vec3 horizontal = dir - up * glm::dot(dir, up);
  if (glm::length(horizontal) < 1e-6f) {
    horizontal = std::fabs(up.x) < 0.9f ? glm::cross(up, glm::vec3(1, 0, 0)) : glm::cross(up, glm::vec3(0, 0, 1));
  }
  horizontal = glm::normalize(horizontal);
  const float yaw = glm::radians(yaw_degrees);
  // Rodrigues about `up` (horizontal is perpendicular to it).
  horizontal = horizontal * std::cos(yaw) + glm::cross(up, horizontal) * std::sin(yaw);
  const float e = glm::radians(new_elevation);
  dir = horizontal * std::cos(e) + up * std::sin(e);
  camera_.position = camera_.target + dir * distance;
  changed();
}

void CameraController::pan(float dx_pixels, float dy_pixels, uint32_t height) {
  const glm::vec3 offset = camera_.target - camera_.position;
  const float distance = glm::length(offset);
  if (!(distance > 0) || height == 0) return;
  const glm::vec3 forward = offset / distance;
  glm::vec3 right = glm::cross(forward, camera_.up);
  if (glm::length(right) < 1e-6f) return;
  right = glm::normalize(right);
  const glm::vec3 up = glm::cross(right, forward);
  // World units per pixel at the target's distance.
  const float scale = 2.0f * distance * std::tan(glm::radians(camera_.fov_degrees) * 0.5f) / height;
  const glm::vec3 move = (-dx_pixels * right + dy_pixels * up) * scale;
  camera_.position += move;
  camera_.target += move;
  changed();
}

void CameraController::zoom(float factor) {
  const glm::vec3 offset = camera_.position - camera_.target;
  if (!(glm::length(offset) > 0) || !(factor > 0)) return;
  camera_.position = camera_.target + offset * factor;
  changed();
}

void CameraController::dolly(float amount) {
  const glm::vec3 offset = camera_.target - camera_.position;
  camera_.position += offset * amount;
  camera_.target += offset * amount;
  changed();
}

void CameraController::frame(const glm::dvec3& lo, const glm::dvec3& hi, float aspect) {
  const glm::vec3 center((lo + hi) * 0.5);
  const float radius = std::max(1e-3f, float(glm::length(hi - lo) * 0.5));
  glm::vec3 dir = camera_.position - camera_.target;
  dir = glm::length(dir) > 0 ? glm::normalize(dir) : glm::vec3(0, 0, 1);
  // The bounding sphere fits the narrower of the two fields of view.
  float half_fov = glm::radians(camera_.fov_degrees) * 0.5f;
  if (aspect < 1) half_fov = std::atan(std::tan(half_fov) * aspect);
  const float distance = radius / std::sin(half_fov);
  camera_.target = center;
  camera_.position = center + dir * distance;
  changed();
}

void CameraController::mouseButton(int button, bool down, bool shift) {
  const int bit = button == 0 ? 1 : button == 1 ? 2 : button == 2 ? 4 : 0;
  if (down)
    buttons_ |= bit;
  else
    buttons_ &= ~bit;
  shift_ = shift;
}

void CameraController::cursor(double x, double y, uint32_t height) {
  const double dx = have_cursor_ ? x - last_x_ : 0, dy = have_cursor_ ? y - last_y_ : 0;
  last_x_ = x;
  last_y_ = y;
  have_cursor_ = true;
  if ((dx == 0 && dy == 0) || buttons_ == 0) return;
  if ((buttons_ & 4) || ((buttons_ & 1) && shift_))
    pan(float(dx), float(dy), height);
  else if (buttons_ & 1)
    orbit(-float(dx) * kOrbitDegreesPerPixel, float(dy) * kOrbitDegreesPerPixel);
  else if (buttons_ & 2)
    dolly(-float(dy) * kDollyPerPixel);
}

void CameraController::scroll(double dy) { zoom(std::pow(kZoomPerWheelStep, float(dy))); }

void CameraController::translate(const glm::dvec3& by) {
  camera_.position = glm::vec3(glm::dvec3(camera_.position) + by);
  camera_.target = glm::vec3(glm::dvec3(camera_.target) + by);
  changed();
}

std::string CameraController::cameraLine(const glm::dvec3& origin) const {
  char line[512];
  const CameraDesc& c = camera_;
  const glm::dvec3 eye = glm::dvec3(c.position) + origin, target = glm::dvec3(c.target) + origin;
  int n = std::snprintf(line, sizeof line,
                        "camera(position: [%.4g, %.4g, %.4g], target: [%.4g, %.4g, %.4g], fov: %.4g",
                        eye.x, eye.y, eye.z, target.x, target.y, target.z, c.fov_degrees);
  std::string text(line, size_t(std::max(n, 0)));
  if (c.up != glm::vec3(0, 1, 0)) {
    std::snprintf(line, sizeof line, ", up: [%.4g, %.4g, %.4g]", c.up.x, c.up.y, c.up.z);
    text += line;
  }
  if (c.aperture > 0) {
    std::snprintf(line, sizeof line, ", aperture: %.4g", c.aperture);
    text += line;
    if (c.focus_distance > 0) {
      std::snprintf(line, sizeof line, ", focus: %.4g", c.focus_distance);
      text += line;
    }
  }
  return text + ")";
}

}  // namespace sdfc::view
