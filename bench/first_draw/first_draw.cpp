// Where the first frame of a new shader goes on lavapipe: pipeline creation,
// then the first draw of the pipeline (llvmpipe compiles the fragment shader to
// machine code there) against the second and third draws of the same pipeline,
// at 1x1 (nearly all compile) and at the view's reload size. Each repetition
// builds a fresh Renderer per size, so every first draw compiles again (run
// with MESA_SHADER_CACHE_DISABLE=true, as bench/view_jit_bench.py does). Wall
// and process CPU times; CPU time holds still on a loaded machine.
//
//   sdfc_first_draw SCENE.sdf [--view NAME] [--reps N] [--size WxH]...
//                   [--write-glsl FILE] [--glsl FILE] [--no-aovs]
// --write-glsl saves the kernel as `sdfc view` emits it; --glsl draws FILE (such
// a kernel, e.g. edited by hand) instead: a quick way to try a kernel change.
// --no-aovs: the beauty kernel without features (EmitOptions::aovs), as `sdfc
// render` emits it for an image nothing denoises.
// Prints one JSON object.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "driver/compile.h"
#include "renderer.h"
#include "scene_render.h"
#include "spirv/glsl_to_spirv.h"
#include "vulkan_context.h"

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// CPU time of the whole process (all threads: lavapipe compiles on its queue
// thread): robust to the machine's load where wall time is not.
double cpuMs() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return (u.ru_utime.tv_sec + u.ru_stime.tv_sec) * 1e3 + (u.ru_utime.tv_usec + u.ru_stime.tv_usec) * 1e-3;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

std::string list(const std::vector<double>& v) {
  std::string s = "[";
  for (size_t i = 0; i < v.size(); ++i) {
    char b[32];
    std::snprintf(b, sizeof b, "%s%.1f", i ? ", " : "", v[i]);
    s += b;
  }
  return s + "]";
}

int usage() {
  std::fprintf(stderr, "usage: sdfc_first_draw SCENE.sdf [--view NAME] [--glsl FILE] [--write-glsl FILE] [--no-aovs] [--reps N] [--size WxH]...\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace sdfc;
  std::string scene_path, glsl_path, write_glsl_path, view_name = "beauty";
  int reps = 3;
  bool aovs = true;
  std::vector<std::pair<int, int>> sizes;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--view" && has_value) view_name = argv[++i];
    else if (a == "--glsl" && has_value) glsl_path = argv[++i];
    else if (a == "--write-glsl" && has_value) write_glsl_path = argv[++i];
    else if (a == "--no-aovs") aovs = false;
    else if (a == "--reps" && has_value) reps = std::max(1, std::atoi(argv[++i]));
    else if (a == "--size" && has_value) {
      const auto size = parseImageSize(argv[++i]);
      if (!size) return usage();
      sizes.push_back(*size);
    } else if (a[0] != '-' && scene_path.empty()) scene_path = a;
    else return usage();
  }
  if (scene_path.empty()) return usage();
  if (sizes.empty()) sizes = {{1, 1}, {160, 90}};
  const char* const names[] = {"beauty", "normal", "steps", "depth", "albedo", "iterations"};
  uint32_t view = 6;
  for (uint32_t v = 0; v < 6; ++v)
    if (view_name == names[v]) view = v;
  if (view == 6) return usage();

  ScopedContext scoped;
  VulkanContext& context = scoped.get();
  // As `sdfc view` compiles it (viewer/view_loop.cpp): its view's kernel, no
  // bound checks on a CPU device.
  CompileOptions options;
  options.emit.view = static_cast<KernelView>(view);
  options.emit.march.image_height = 360;
  options.emit.aovs = aovs;
  if (context.properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU) options.emit.bounding_volumes = false;
  Diagnostics diags;
  CompiledScene compiled = compileFile(scene_path, options, diags);
  if (!compiled.ok) {
    std::fprintf(stderr, "sdfc_first_draw: %s does not compile\n", scene_path.c_str());
    return 1;
  }
  if (!write_glsl_path.empty()) std::ofstream(write_glsl_path) << compiled.emitted.glsl;
  std::vector<uint32_t> spirv = compiled.spirv;
  if (!glsl_path.empty()) {
    std::ifstream in(glsl_path);
    std::stringstream text;
    text << in.rdbuf();
    const SpirvResult r = glslToSpirv(text.str(), ShaderStage::Fragment, glsl_path);
    if (!r.ok()) {
      std::fprintf(stderr, "%s\n", r.log.c_str());
      return 1;
    }
    spirv = r.words;
  }

  // What the CPU camera-inside test costs at each accumulation start (the view
  // calls it on the frame loop, between a save's pipeline and its first frame).
  std::vector<double> inside_us;
  const CameraDesc file_camera = cameraFor(compiled.scene);
  for (int r = 0; r < 9; ++r) {
    const auto start = Clock::now();
    volatile bool inside = cameraInside(compiled.scene, compiled.emitted.limits, file_camera.position, float(r));
    (void)inside;
    inside_us.push_back(msSince(start) * 1000);
  }
  std::printf("{\"camera_inside_us\": %s, \"median_camera_inside_us\": %.1f, ", list(inside_us).c_str(),
              median(inside_us));
  std::printf("\"scene\": \"%s\", \"view\": \"%s\", \"glsl\": \"%s\", \"device\": \"%s\", "
              "\"driver\": \"%s\", \"aovs\": %s, \"spirv_bytes\": %zu, \"sizes\": [",
              scene_path.c_str(), view_name.c_str(), glsl_path.c_str(), context.deviceName().c_str(),
              driverText(context.physical_device).c_str(), aovs ? "true" : "false", spirv.size() * 4);
  for (size_t s = 0; s < sizes.size(); ++s) {
    std::vector<double> pipeline, draw1, draw2, draw3, pipeline_cpu, draw1_cpu;
    for (int r = 0; r < reps; ++r) {
      auto start = Clock::now();
      double cpu = cpuMs();
      Renderer renderer(context, spirv, compiled.emitted.scene_data);
      renderer.setCameraInsideTest(cameraInsideTest(compiled.scene, compiled.emitted.limits));
      pipeline.push_back(msSince(start));
      pipeline_cpu.push_back(cpuMs() - cpu);
      RenderOverrides o;
      o.width = sizes[s].first;
      o.height = sizes[s].second;
      o.view = view;
      RenderSettings settings = renderSettingsFor(compiled, o);
      settings.band_pixels = 1u << 21;  // one band, as the view draws
      Accumulation acc = renderer.startAccumulation(cameraFor(compiled.scene), settings, false);
      for (std::vector<double>* draws : {&draw1, &draw2, &draw3}) {
        start = Clock::now();
        cpu = cpuMs();
        renderer.addPass(acc, 1);
        draws->push_back(msSince(start));
        if (draws == &draw1) draw1_cpu.push_back(cpuMs() - cpu);
      }
    }
    std::printf("%s{\"size\": \"%dx%d\", \"pipeline_ms\": %s, \"draw1_ms\": %s, \"draw2_ms\": %s, "
                "\"draw3_ms\": %s, \"pipeline_cpu_ms\": %s, \"draw1_cpu_ms\": %s, "
                "\"median_pipeline_ms\": %.1f, \"median_draw1_ms\": %.1f, \"median_draw2_ms\": %.1f, "
                "\"median_jit_ms\": %.1f, \"median_pipeline_cpu_ms\": %.1f, \"median_draw1_cpu_ms\": %.1f}",
                s ? ", " : "", sizes[s].first, sizes[s].second, list(pipeline).c_str(), list(draw1).c_str(),
                list(draw2).c_str(), list(draw3).c_str(), list(pipeline_cpu).c_str(), list(draw1_cpu).c_str(),
                median(pipeline), median(draw1), median(draw2), median(draw1) - median(draw2),
                median(pipeline_cpu), median(draw1_cpu));
  }
  std::printf("]}\n");
  return validationMessageCount() == 0 ? 0 : 3;
}
