#include "nlr_input.h"

#include <sys/resource.h>

#include <cstdio>

#include "scene_render.h"
#include "vulkan_context.h"

namespace sdfc::bench {

bool renderNlrInput(const std::string& scene_path, std::pair<int, int> size, int spp, int seed, const char* tool,
                    NlrInput& input) {
  ScopedContext scoped;
  VulkanContext& context = scoped.get();
  CompileOptions options;
  options.emit.march.image_height = size.second;
  adaptCompileOptionsToDevice(options, context.properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU, false);
  Diagnostics diags;
  const CompiledScene compiled = compileFile(scene_path, options, diags);
  if (!compiled.ok) {
    std::fprintf(stderr, "%s: %s does not compile\n", tool, scene_path.c_str());
    return false;
  }
  Renderer renderer(context, compiled);
  RenderOverrides o;
  o.width = size.first;
  o.height = size.second;
  o.spp = spp;
  o.seed = uint32_t(seed);
  RenderSettings settings = renderSettingsFor(compiled, o);
  // As renderImage sets them for nlr (api/scene_render.cpp).
  settings.jittered_aovs = true;
  settings.specular_aovs = true;
  settings.read_features = true;
  input.out = renderHalves(renderer, cameraFor(compiled.scene), settings, &input.halves);
  resolveJitteredAovs(input.out, &input.halves);
  return true;
}

double processCpuMs() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return (u.ru_utime.tv_sec + u.ru_stime.tv_sec) * 1e3 + (u.ru_utime.tv_usec + u.ru_stime.tv_usec) * 1e-3;
}

}  // namespace sdfc::bench
