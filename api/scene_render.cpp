#include "scene_render.h"

#include <chrono>
#include <ctime>

#include "option_limits.h"
#include "check/checker.h"
#include "loop_budget.h"
#include "vk_check.h"

namespace sdfc {

std::optional<std::pair<int, int>> parseImageSize(const std::string& text) {
  // WxH, each 1 to 5 digits; scanned by hand (std::regex recurses per character).
  const size_t x = text.find('x');
  auto whole = [](std::string_view s) {
    return !s.empty() && s.size() <= 5 && s.find_first_not_of("0123456789") == std::string_view::npos;
  };
  if (x == std::string::npos || !whole(std::string_view(text).substr(0, x)) ||
      !whole(std::string_view(text).substr(x + 1)))
    return std::nullopt;
  const int w = std::stoi(text.substr(0, x)), h = std::stoi(text.substr(x + 1));
  const api::OptionLimit& side = api::optionLimit(api::Option::Size);
  if (w < side.lo || h < side.lo || w > side.hi || h > side.hi) return std::nullopt;
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

uint32_t viewIdFromName(const std::string& v) {
  if (v == "normal") return gpu::kViewNormal;
  if (v == "steps") return gpu::kViewSteps;
  if (v == "depth") return gpu::kViewDepth;
  if (v == "albedo") return gpu::kViewAlbedo;
  if (v == "iterations") return gpu::kViewIterations;
  return gpu::kViewBeauty;
}

void adaptCompileOptionsToDevice(CompileOptions& options, bool cpu_device, bool force_bounds) {
  if (cpu_device && !force_bounds) {
    options.emit.bounding_volumes = false;
    options.emit.planned_bounds = true;  // only the checks that pay here
  }
}

bool imageReadsFeatures(uint32_t view, uint32_t spp, const ImageOptions& options) {
  if (view != gpu::kViewBeauty) return false;
  if (options.draw) return true;  // adaptive sampling: its own use of them
  if (options.layers) return true;
  const Denoiser denoiser = options.denoiser.value_or(Denoiser::Nlr);
  if (denoiser == Denoiser::None) return false;
  // A variance-guided denoiser leaves a 1-spp image as it is (no second half).
  return !needsVariance(denoiser) || spp >= 2;
}

RenderedImage renderImage(Renderer& renderer, const CompiledScene& compiled, RenderSettings settings,
                          const ImageOptions& options, const ProgressCallback& progress,
                          const std::atomic<bool>* interrupt) {
  RenderedImage result;
  const bool beauty = settings.view == gpu::kViewBeauty;
  const std::optional<Denoiser> denoiser = options.denoiser ? options.denoiser : Denoiser::Nlr;
  // The variance-guided denoiser renders the samples as two halves: their
  // difference is its per-pixel noise estimate.
  SampleHalves halves;
  const bool custom = options.draw && beauty;
  const bool with_halves = custom || (beauty && denoiser && needsVariance(*denoiser));
  // Their features are the means of the same jittered samples as the colour
  // (docs/denoise.md): at an edge they blend as the colour does.
  const std::string& aovs = options.denoise_aovs;
  settings.jittered_aovs = with_halves && denoiser && needsVariance(*denoiser) &&
                           (aovs == "jittered" || aovs == "specular" ||
                            (aovs == "auto" && wantsJitteredAovs(*denoiser)));
  // Through specular first hits (docs/denoise.md).
  settings.specular_aovs =
      settings.jittered_aovs && (aovs == "specular" || (aovs == "auto" && wantsSpecularAovs(*denoiser)));
  settings.read_features = imageReadsFeatures(settings.view, settings.spp, options);
  if (settings.read_features && compiled.emitted.stats.features.count("SDFC_NO_AOVS"))
    throw RuntimeError("internal error: a denoised image from a kernel emitted without features");
  const CameraDesc camera = cameraFor(compiled.scene);
  RenderOutput& out = result.out;
  // Without two halves (1 spp, or interrupted early) svgf and nlm leave the image as it is.
  auto denoises = [&] {
    return beauty && denoiser && *denoiser != Denoiser::None && (!with_halves || halves.samples_b > 0);
  };
  // One bar over the samples and the denoise (docs/denoise.md has its cost).
  const bool may_denoise = beauty && denoiser && *denoiser != Denoiser::None &&
                           (!needsVariance(*denoiser) || settings.spp >= 2);
  JobProgress job(progress, beauty ? std::max<uint32_t>(settings.spp, 1) : 1,
                  may_denoise ? predictedDenoiseSeconds(*denoiser, size_t(settings.width) * settings.height,
                                                        options.denoise_select.size())
                              : 0.0);
  const ProgressCallback samples = progress ? job.samples() : ProgressCallback{};
  if (custom) {
    out = options.draw(renderer, camera, settings, &halves, samples);
  } else {
    out = with_halves ? renderHalves(renderer, camera, settings, &halves, samples, interrupt)
                      : renderer.render(camera, settings, samples, interrupt);
  }
  if (settings.jittered_aovs) resolveJitteredAovs(out, &halves);
  // An interrupted render is written as it is, at once (the raw mean of its samples).
  if (denoises() && !out.interrupted) {
    const auto start = std::chrono::steady_clock::now();
    // Process CPU time: the device is idle meanwhile, so this is the filter's own.
    const std::clock_t cpu_start = std::clock();
    job.startStage("denoising");
    DenoiseControl control;
    control.interrupt = interrupt;
    if (progress) control.progress = [&job](double share) { job.stageProgress(share); };
    result.denoised = denoise(*denoiser, out.color, out.normal_depth, out.albedo_steps, &halves,
                              options.denoise_select, control);
    if (result.denoised.empty()) {  // stopped by the interrupt
      out.interrupted = true;
      result.denoise_interrupted = true;
    } else {
      result.denoiser = *denoiser;
    }
    result.denoise_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    result.denoise_cpu_seconds = double(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  }
  job.finish(out.samples_done, out.passes, out.interrupted);
  result.settings = settings;
  return result;
}

}  // namespace sdfc
