// sdfc's public API, part 2: renders a compiled scene on a Vulkan device, the
// bridge between compiler output (SPIR-V, march limits, scene settings) and the
// runtime: settings from the scene overridden field by field, one still image
// with its denoiser (what `sdfc render` writes), progress and cancellation.
// Used by `sdfc render`, the viewer, the Python module, the benchmark and the
// image tests.
#pragma once
#include <atomic>
#include <functional>
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

// "beauty", "normal", "steps", "depth", "albedo", "iterations" -> gpu::kView*
// (anything else: beauty).
uint32_t viewIdFromName(const std::string& name);

// `options` for the device the kernel will run on: lavapipe runs lanes in
// lockstep, so a bounding-volume check pays only where whole groups skip; on a
// CPU device the compiler keeps those it plans to pay (passes/bounds_plan.cpp),
// all of them with `force_bounds`.
void adaptCompileOptionsToDevice(CompileOptions& options, bool cpu_device, bool force_bounds);

// How a still image's samples are treated, beyond RenderSettings.
struct ImageOptions {
  // nullopt: nlr for the beauty view (the command line's default); the debug
  // views are never denoised.
  std::optional<Denoiser> denoiser;
  std::string denoise_aovs = "auto";  // auto | jittered | specular | centre
  std::vector<float> denoise_select;  // nlm/nlr per-pixel strengths; empty: off
  // Draws the samples instead of renderHalves (adaptive sampling, cli/); called
  // with halves that it fills, and the progress callback to report the samples to.
  std::function<RenderOutput(Renderer&, const CameraDesc&, const RenderSettings&, SampleHalves*,
                             const ProgressCallback&)>
      draw;
  // --layers: the caller writes the primary ray's normal, depth and albedo.
  bool layers = false;
};

// Whether renderImage reads the features (normal, depth, albedo) of a render of
// `view` at `spp` samples per pixel: only when a denoiser runs on them (the
// beauty view, a denoiser other than none, and two halves when it needs them),
// or when the caller writes them as layers.
// False: the kernel may be emitted without them (EmitOptions::aovs) and the
// render reads back only the colour and the march steps (read_features).
bool imageReadsFeatures(uint32_t view, uint32_t spp, const ImageOptions& options);

struct RenderedImage {
  RenderOutput out;        // the samples' mean and features
  FloatImage denoised;     // empty when not denoised
  RenderSettings settings;
  Denoiser denoiser = Denoiser::None;  // what was applied
  bool denoise_interrupted = false;    // the interrupt stopped the denoiser (out.interrupted too)
  double denoise_seconds = 0, denoise_cpu_seconds = 0;
  const FloatImage& image() const { return denoised.empty() ? out.color : denoised; }
};

// One still, exactly as `sdfc render` makes it: two halves when the denoiser
// needs a noise estimate, jittered features where it wants them, denoised.
// `settings` from renderSettingsFor. Throws RuntimeError on device errors;
// an interrupt stops after the current pass (out.interrupted; no denoise then)
// or stops the denoiser (denoise_interrupted). `progress` gets one bar over the
// samples and the denoise (JobProgress) and one finished call.
RenderedImage renderImage(Renderer& renderer, const CompiledScene& compiled, RenderSettings settings,
                          const ImageOptions& options, const ProgressCallback& progress = {},
                          const std::atomic<bool>* interrupt = nullptr);

}  // namespace sdfc
