#include "scene_render.h"

#include <regex>

#include "check/checker.h"
#include "loop_budget.h"

namespace sdfc {

std::optional<std::pair<int, int>> parseImageSize(const std::string& text) {
  std::smatch m;
  if (!std::regex_match(text, m, std::regex(R"((\d{1,5})x(\d{1,5}))"))) return std::nullopt;
  const int w = std::stoi(m[1]), h = std::stoi(m[2]);
  if (w < 1 || h < 1 || w > 16384 || h > 16384) return std::nullopt;
  return std::make_pair(w, h);
}
// The checker refuses more lights than the kernel's light loop is budgeted for.
static_assert(kMaxLights == kMaxSphereLights, "checker.h and loop_budget.h disagree on the light limit");

RenderSettings renderSettingsFor(const CompiledScene& compiled, const RenderOverrides& o) {
  const ir::RenderSettings& r = compiled.scene.render;
  RenderSettings s;
  s.width = static_cast<uint32_t>(o.width.value_or(r.width));
  s.height = static_cast<uint32_t>(o.height.value_or(r.height));
  s.spp = static_cast<uint32_t>(o.spp.value_or(r.spp));
  s.max_bounces = static_cast<uint32_t>(o.bounces.value_or(r.bounces));
  s.light_samples = static_cast<uint32_t>(o.light_samples.value_or(r.light_samples));
  s.view = o.view;
  s.seed = o.seed;
  s.time = static_cast<float>(o.time);
  const uint32_t steps = static_cast<uint32_t>(compiled.emitted.limits.max_steps);
  const uint32_t lights = static_cast<uint32_t>(compiled.scene.lights.size());
  s.loop_iterations_per_sample = loopIterationsPerSample(steps, s.max_bounces, s.light_samples, lights);
  s.loop_iterations_per_pass = loopIterationsPerPassOverhead(steps, lights);
  s.instance_sets = static_cast<uint32_t>(compiled.emitted.stats.traversals_per_evaluation);
  return s;
}

CameraDesc cameraFor(const ir::Scene& scene) {
  const ir::Camera& c = scene.camera;
  CameraDesc d;
  d.position = glm::vec3(c.position);
  d.target = glm::vec3(c.target);
  d.up = glm::vec3(c.up);
  d.fov_degrees = static_cast<float>(c.fov_degrees);
  d.aperture = static_cast<float>(c.aperture);
  d.focus_distance = static_cast<float>(c.focus_distance);
  return d;
}

}  // namespace sdfc
