// Renders a compiled scene on a Vulkan device: the bridge between compiler
// output (SPIR-V, march limits, scene settings) and the runtime. Used by
// `sdfc render`, the benchmark and the image tests.
#pragma once
#include <atomic>
#include <optional>
#include <string>

#include "driver/compile.h"
#include "denoise.h"
#include "renderer.h"
#include "vulkan_context.h"

namespace sdfc {

// Settings the command line may override; unset ones come from the scene.
struct RenderOverrides {
  std::optional<int> width, height, spp, bounces, light_samples;
  uint32_t view = gpu::kViewBeauty;
  uint32_t seed = 0;
  double time = 0;
};

// "WxH" with sides 1..16384 -> {W, H}; nullopt otherwise.
std::optional<std::pair<int, int>> parseImageSize(const std::string& text);

RenderSettings renderSettingsFor(const CompiledScene& compiled, const RenderOverrides& o);
CameraDesc cameraFor(const ir::Scene& scene);

}  // namespace sdfc
