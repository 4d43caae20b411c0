// `sdfc render`: compile, render progressively on the Vulkan device, denoise,
// write the image (or a frame sequence over time).
#include <chrono>
#include <future>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>

#include "adaptive.h"
#include "debug_view.h"
#include "cli_support.h"
#include "commands.h"
#include "image_io.h"
#include "render_defaults.h"
#include "render_layers.h"
#include "progress.h"
#include "scene_render.h"
#include "pipeline_cache.h"
#include "reuse_freed_memory.h"
#include "spirv/spirv_cache.h"
#include "stage_timings.h"
#include "shard_plan.h"
#include "driver_select.h"
#include "driver_compile_level.h"
#include "farm_support.h"
#include "cli_support.h"

namespace sdfc {
namespace {

constexpr double kMaxFrames = 100000;

// What to write instead of the old --frames A-B:step (times in seconds).
std::string framesHint(const std::string& text) {
  // A-B:step, split by hand (std::regex recursed per character and overflowed
  // the stack on a 100,000-character step). B may be negative ("1--2:1").
  std::optional<double> a, b, step;
  std::string m[4];
  const size_t colon = text.rfind(':');
  const size_t dash = colon == std::string::npos || colon < 2 ? std::string::npos : text.find('-', 1);
  if (dash != std::string::npos && dash < colon) {
    m[1] = text.substr(0, dash);
    m[2] = text.substr(dash + 1, colon - dash - 1);
    m[3] = text.substr(colon + 1);
    a = parsePlainNumber(m[1]);
    b = parsePlainNumber(m[2]);
    step = parsePlainNumber(m[3]);
  }
  if (a && b && step && *step > 0 && *b >= *a) {
    const double fps = 1 / *step, first = *a * fps, last = *b * fps;
    auto whole = [](double x) { return std::fabs(x - std::round(x)) < 1e-6 && std::fabs(x) < 1e6; };
    if (whole(first) && whole(last) && first >= 0) {
      char hint[160];
      std::snprintf(hint, sizeof hint, "for times %s to %s every %s s write --frames %.0f-%.0f --fps %.9g",
                    m[1].c_str(), m[2].c_str(), m[3].c_str(), first, last, fps);
      return hint;
    }
  }
  return "e.g. --frames 0-47 --fps 24 renders 2 s (--time T renders one instant)";
}

}  // namespace

LoadedScene compileForDevice(const CommandLine& cl, const VulkanContext& context,
                             const RenderOverrides& o) {
  CompileOptions options = compileOptionsFrom(cl);
  if (o.height) options.emit.march.image_height = *o.height;
  // Lavapipe runs 8 lanes in lockstep: a bounding-volume check pays only where
  // whole groups skip, so the compiler plans which to keep (planned_bounds,
  // passes/bounds_plan.cpp; bench/results/bounds_plan.md).
  if (context.properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU && !cl.force_bounds)
    options.emit.bounding_volumes = false;
  Diagnostics diags;
  return loadScene(cl, diags, true, true, options, true);
}

LoadedScene compileForCpuDevice(const CommandLine& cl, const RenderOverrides& o, bool features) {
  CompileOptions options = compileOptionsFrom(cl);
  if (o.height) options.emit.march.image_height = *o.height;
  options.emit.aovs = features;
  if (!cl.force_bounds) options.emit.bounding_volumes = false;  // as compileForDevice on a CPU
  Diagnostics diags;
  return loadScene(cl, diags, true, true, options, true);
}

void adaptToDevice(LoadedScene& loaded, const CommandLine& cl, const VulkanContext& context,
                   const RenderOverrides& o, bool features) {
  if (loaded.exit_code != kExitOk || cl.force_bounds || cl.no_bounds ||
      context.properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU)
    return;
  // A GPU jumps over a bounding volume's subtree: the kernel with bounds.
  const auto start = std::chrono::steady_clock::now();
  CompileOptions options = compileOptionsFrom(cl);
  if (o.height) options.emit.march.image_height = *o.height;
  options.emit.aovs = features;
  CompiledScene& c = loaded.compiled;
  c.emitted = emitGlsl(c.scene, options.emit);
  SpirvResult spv = options.spirv_cache
                        ? cachedGlslToSpirv(c.emitted.glsl, ShaderStage::Fragment, c.source->path + ".glsl",
                                            options.optimize_spirv, true, options.cache_version)
                        : glslToSpirv(c.emitted.glsl, ShaderStage::Fragment, c.source->path + ".glsl",
                                      options.optimize_spirv, true);
  if (!spv.ok())
    throw std::runtime_error("internal error: the generated shader does not compile:\n" + spv.log);
  c.spirv = std::move(spv.words);
  c.times.device_emit = secondsSince(start);
}

namespace {

// --adaptive-budget time, --adaptive-cost iterations: the kernel's own loop-iteration
// count of one sample per pixel at half size, as a cost per sample at the render's
// size (iterationsCost). Its compile, pipeline and pass are part of the render's time.
int iterationsCostPass(const CommandLine& cl, const VulkanContext& context, const RenderOverrides& o,
                       const RenderSettings& settings, const CameraDesc& camera,
                       std::vector<float>& cost) {
  CommandLine iterations_cl = cl;
  iterations_cl.view = "iterations";
  RenderOverrides io = o;
  io.view = gpu::kViewIterations;
  io.width = std::max<uint32_t>(1, settings.width / 2);
  io.height = std::max<uint32_t>(1, settings.height / 2);
  LoadedScene scene = compileForDevice(iterations_cl, context, io);
  if (scene.exit_code != kExitOk) return scene.exit_code;
  Renderer renderer(context, scene.compiled);
  RenderSettings is = renderSettingsFor(scene.compiled, io);
  is.spp = 1;
  cost = iterationsCost(renderer.render(camera, is).color, settings.width, settings.height);
  return kExitOk;
}

// --adaptive and --layers against the flags they cannot go with (usage errors).
bool checkLayersFlags(const CommandLine& cl) {
  if (cl.adaptive && (cl.shards > 0 || cl.shard_index >= 0)) {
    std::cerr << "sdfc: error: --adaptive cannot be split into --shards (its counts depend on the "
                 "whole first phase)\n";
    return false;
  }
  if (cl.layers) {
    // One multi-channel EXR of the raw samples and the primary ray's layers
    // (docs/layers.md): nothing else holds them, and a filtered beauty would
    // no longer match its own variance.
    const char* other = cl.view != "beauty" && !cl.view.empty() ? "--view"
                        : cl.adaptive                          ? "--adaptive"
                        : !cl.denoiser.empty() && cl.denoiser != "none" ? "--denoise"
                                                                        : nullptr;
    if (other) {
      std::cerr << "sdfc: error: --layers does not go with " << other
                << ": it writes the raw mean of uniform samples and the primary ray's layers "
                   "(docs/layers.md)\n";
      return false;
    }
    // With --shards, -o is the shard directory; `sdfc merge` writes the EXR.
    const bool shards = cl.shards > 0 || cl.shard_index >= 0;
    bool exr = false;
    try {
      exr = imageFormatFromPath(cl.output) == ImageFormat::Exr;
    } catch (const std::exception&) {
    }
    if (!exr && !shards) {
      std::cerr << "sdfc: error: --layers writes one multi-channel EXR: -o '" << cl.output
                << "' must end in .exr\n";
      return false;
    }
  }
  return true;
}

// Flags that act on the finished image, refused with --shards (a usage error).
bool checkShardFlags(const CommandLine& cl) {
  // A shard holds raw sample sums and `sdfc merge` writes them undenoised and
  // untoned: flags that act on the finished image would be dropped unseen.
  const char* image_flag = !cl.denoiser.empty() && cl.denoiser != "none" ? "--denoise"
                           : !cl.denoise_select.empty()  ? "--denoise-select"
                           : cl.denoise_aovs != "auto"   ? "--denoise-aovs"
                           : cl.exposure != 0            ? "--exposure"
                           : cl.aces                     ? "--aces"
                           : cl.tonemap != "neutral"     ? "--tonemap"
                                                         : nullptr;
  if (image_flag) {
    std::cerr << "sdfc: error: " << image_flag
              << " does not apply to --shards: a shard holds sample sums, and `sdfc merge` writes "
                 "their exact mean, undenoised and untoned (render without --shards to use it)\n";
    return false;
  }
  return true;
}

// Frame sequence: frame numbers A-B at --fps (time = frame / fps), the same
// meaning as with --shards and `farm submit`. The count is decided (and
// limited) before any list is built or any work starts.
bool framesFrom(const CommandLine& cl, std::vector<double>& times, std::vector<int>& frame_numbers) {
  if (!cl.frames.empty()) {
    if (cl.frames.find(':') != std::string::npos) {
      std::cerr << "sdfc: error: --frames takes frame numbers A-B at --fps (default 24), not "
                   "times A-B:step; " << framesHint(cl.frames) << "\n";
      return false;
    }
    std::pair<int, int> range;
    try {
      range = farm::parseFrameRange(cl.frames);
    } catch (const std::exception& e) {
      std::cerr << "sdfc: error: " << e.what() << "\n";
      return false;
    }
    const double count = static_cast<double>(range.second) - range.first + 1;
    if (!(count <= kMaxFrames)) {
      std::cerr << "sdfc: error: --frames " << cl.frames << " gives " << count << " frames; at most "
                << kMaxFrames << "\n";
      return false;
    }
    times.clear();
    for (int frame = range.first; frame <= range.second; ++frame) {
      frame_numbers.push_back(frame);
      times.push_back(frame / cl.fps);
    }
  }
  return true;
}

// --adaptive's parameters from their flags (docs/adaptive.md).
AdaptiveParams adaptiveParamsFrom(const CommandLine& cl) {
  AdaptiveParams params;
  params.estimate = *parseAdaptiveEstimate(cl.adaptive_estimate);
  params.first_share = cl.adaptive_share;
  params.cap = cl.adaptive_cap;
  params.block = cl.adaptive_block;
  params.power = cl.adaptive_power;
  params.time_budget = cl.adaptive_budget == "time";
  params.cost_offset = cl.adaptive_cost_offset;
  return params;
}

// The primary rays' march steps (and, for --view iterations, the loop counts)
// after a frame: a warning for rays that ran out, the figures unless --quiet.
void reportMarchSteps(const CommandLine& cl, uint32_t view, const RenderOutput& out, uint32_t max_steps) {
  {
    // A primary ray that used its whole step budget ran out of steps: it is
    // drawn as a hit when it was still closing in, else as a miss; either way
    // its pixel may be off, so say how many (issue 17).
    const size_t pixels = size_t(out.albedo_steps.width) * out.albedo_steps.height;
    const float budget = static_cast<float>(max_steps);
    size_t exhausted = 0;
    for (size_t i = 0; i < pixels; ++i) exhausted += out.albedo_steps.rgba[i * 4 + 3] >= budget;
    if (exhausted > 0)
      std::cerr << "sdfc: warning: " << exhausted << " of " << pixels
                << " primary rays ran out of march steps (budget " << budget << ")\n";
  }
  if (!cl.quiet) {
    // Primary-ray march steps (attachment 2, w): the cost figure bounds are judged by.
    double sum = 0, peak = 0;
    const size_t pixels = size_t(out.albedo_steps.width) * out.albedo_steps.height;
    for (size_t i = 0; i < pixels; ++i) {
      sum += out.albedo_steps.rgba[i * 4 + 3];
      peak = std::max<double>(peak, out.albedo_steps.rgba[i * 4 + 3]);
    }
    std::cerr << "sdfc: primary ray steps: mean " << (pixels ? sum / pixels : 0) << ", max " << peak
              << " (budget " << max_steps << ")\n";
    if (view == gpu::kViewIterations) {
      double total = 0, most = 0;
      for (size_t i = 0; i < pixels; ++i) {
        total += out.color.rgba[i * 4];
        most = std::max<double>(most, out.color.rgba[i * 4]);
      }
      std::cerr << "sdfc: loop iterations" << (cl.count_evaluations ? " + primitive evaluations" : "")
                << " per pixel: mean " << (pixels ? total / pixels : 0) << ", max " << most << "\n";
      if (!cl.count_event.empty()) {
        double events = 0;
        for (size_t i = 0; i < pixels; ++i) events += out.color.rgba[i * 4 + 1];
        std::cerr << "sdfc: " << cl.count_event << " per pixel: mean " << (pixels ? events / pixels : 0) << "\n";
      }
    }
  }
}

}  // namespace

int runRender(const CommandLine& cl) {
  RenderOverrides o;
  if (!renderOverridesFrom(cl, o)) return kExitUsage;
  o.view = viewIdFromName(cl.view);
  if (!checkLayersFlags(cl)) return kExitUsage;
  if (cl.shards > 0 || cl.shard_index >= 0) {
    if (!checkShardFlags(cl)) return kExitUsage;
    return runRenderShard(cl, o);
  }
  // A still, or a sequence of frames at --fps.
  std::vector<double> times = {cl.time};
  std::vector<int> frame_numbers;  // empty: a still, written to -o as it is
  if (!framesFrom(cl, times, frame_numbers)) return kExitUsage;
  // Each frame's filter reuses the memory of the one before (runtime/reuse_freed_memory.h).
  if (times.size() > 1) reuseFreedMemory();
  // The defaults (spp, denoiser, adaptive, the kernel's features) are decided in
  // api/render_defaults.h; here from the command line alone, the scene is not read yet.
  RenderRequest request;
  if (o.spp) request.spp = *o.spp;
  if (!cl.denoiser.empty()) request.denoiser = parseDenoiser(cl.denoiser);
  request.view = o.view;
  request.layers = cl.layers;
  request.adaptive = cl.adaptive;
  request.frames = times.size();
  request.denoise_select = !cl.denoise_select.empty();
  RenderChoice choice = chooseRenderSettings(request, nullptr);
  // Check the output's extension (a usage error) and directory before any work.
  if (!checkImageExtension(cl.output)) return kExitUsage;
  checkWritablePath(frame_numbers.empty() ? cl.output : farm::framePath(cl.output, frame_numbers[0]));

  // The driver's pipeline cache beside the SPIR-V cache (runtime/pipeline_cache.h).
  if (!cl.no_cache) setPipelineCacheDirectory(sdfcCacheDirectory());
  // --timings: printed after the device is destroyed (declared before it).
  StageTimings timings;
  struct PrintTimings {
    const StageTimings& timings;
    bool on;
    ~PrintTimings() {
      if (on) timings.print();
    }
  } print_timings{timings, cl.stage_timings};
  timings.add("process start to main", processStartToMainSeconds(), "(one clock tick: 10 ms)");
  timings.add("command line and checks", secondsSinceMain());

  ContextOptions context_options;
  context_options.device_index = cl.device;
  std::optional<ScopedContext> scoped_context;
  // Destroyed before print_timings: its time is the last stage.
  struct DestroyContext {
    std::optional<ScopedContext>& context;
    StageTimings& timings;
    ~DestroyContext() {
      const auto start = std::chrono::steady_clock::now();
      context.reset();
      timings.add("device destruction", secondsSince(start));
    }
  } destroy_context{scoped_context, timings};
  // The device does not depend on the scene: it is created beside the front
  // end and glslang. The kernel is compiled for a CPU device (lavapipe, the
  // usual one) meanwhile, and emitted again if the device turns out not to be one.
  double device_seconds = 0;
  selectedDriver();  // sets the loader's variables here: setenv beside getenv is unsafe
  // A render of few samples: lavapipe's LLVM without its optimisation passes
  // (driver_compile_level.h). Decided from the command line only: the scene's
  // own render() settings are not read yet.
  const bool quick_compile =
      o.width && o.height && (o.spp || o.view != gpu::kViewBeauty) &&
      chooseQuickDriverCompile(uint64_t(*o.width) * uint64_t(*o.height) *
                               uint64_t(o.view == gpu::kViewBeauty ? *o.spp : 1) * times.size());
  // A beauty render whose image nothing denoises gets the kernel without
  // features: smaller to compile (bench/results/fixed_costs.md).
  const bool features = choice.kernel_features;
  // Ctrl-C: until a frame has samples, the process ends at once (exit 130,
  // nothing written); then the render stops after its pass, the denoiser
  // between blocks of pixels, and what was sampled is written.
  const std::atomic<bool>* interrupt = installInterruptHandler(true);
  std::future<void> device = std::async(std::launch::async, [&] {
    const auto start = std::chrono::steady_clock::now();
    scoped_context.emplace(context_options);
    device_seconds = secondsSince(start);
  });
  const auto compile_start = std::chrono::steady_clock::now();
  LoadedScene loaded = compileForCpuDevice(cl, o, features);
  const double compile_seconds = secondsSince(compile_start);
  const auto device_wait_start = std::chrono::steady_clock::now();
  device.get();  // rethrows a device error (exit 3)
  const double device_wait = secondsSince(device_wait_start);
  timings.add("device creation", device_seconds, "(beside the compile)", true);
  timings.add("waited for the device", device_wait, "(after the compile's " +
              std::to_string(std::lround(compile_seconds * 1000)) + " ms)");
  if (loaded.exit_code != kExitOk) return loaded.exit_code;
  // loadScene checked -o itself; a sequence's frames are other names.
  for (int frame : frame_numbers)
    if (outputIsAnInput(farm::framePath(cl.output, frame), cl.input, loaded.compiled)) return kExitUsage;
  VulkanContext& context = scoped_context->get();
  adaptToDevice(loaded, cl, context, o, features);
  const CompiledScene& compiled = loaded.compiled;
  {
    const StageTimes& t = compiled.times;
    timings.add("front end (parse, check, passes)", t.parse + t.check + t.passes);
    timings.add("emit GLSL", t.emit,
                compiled.emitted.stats.features.count("SDFC_NO_AOVS") ? "(no AOV features: nothing denoises)" : "");
    if (t.spirv_cached) {
      timings.add("SPIR-V from the cache", t.spirv, "(glslang and validation skipped)");
    } else {
      timings.add("glslang", t.spirv - t.validate, cl.no_cache ? "(--no-cache)" : "(cache miss; stored)");
      timings.add("SPIR-V validation", t.validate);
    }
    if (t.device_emit > 0) {
      timings.add("kernel again for a GPU (with bounds)", t.device_emit);
    }
  }

  const auto renderer_start = std::chrono::steady_clock::now();
  Renderer renderer(context, compiled);
  timings.add("pipeline creation", secondsSince(renderer_start),
              "(vkCreateGraphicsPipelines " + std::to_string(std::lround(renderer.pipelineSeconds() * 1000)) +
                  " ms; the vertex shader, scene buffer)");
  ToneMap tone;
  tone.exposure_stops = static_cast<float>(cl.exposure);
  tone.curve = cl.aces ? ToneCurve::AcesFit : *toneCurveFromName(cl.tonemap);
  const bool quiet = cl.quiet;
  if (!quiet)
    std::cerr << "sdfc: device " << context.deviceName() << ", " << driverText(context.physical_device)
              << (selectedDriver().bundled ? " (bundled lavapipe)" : "") << "\n";
  if (!quiet)
    std::cerr << "sdfc: compiled in " << std::lround(compiled.times.total() * 1000) << " ms (parse+check "
              << std::lround((compiled.times.parse + compiled.times.check + compiled.times.passes) * 1000)
              << ", emit " << std::lround(compiled.times.emit * 1000) << ", SPIR-V "
              << std::lround(compiled.times.spirv * 1000)
              << (compiled.times.spirv_cached ? " from the cache" : "") << "), pipeline in "
              << std::lround(renderer.pipelineSeconds() * 1000) << " ms\n";
  if (!quiet && cl.prune) {
    // What --prune did: the grid, or why there is none.
    const ir::Node* root = compiled.scene.root.get();
    if (root && root->prune) {
      const ir::PruneGrid& g = *root->prune;
      std::cerr << "sdfc: --prune: " << g.prunedParts() << " of " << g.parts.size() << " parts on " << g.dims.x << "x"
                << g.dims.y << "x" << g.dims.z << " cells; a cell near a surface keeps "
                << std::lround(100 * g.kept_cost_near) << "% of their cost\n";
    } else {
      std::cerr << "sdfc: --prune: no grid: the scene's top-level union has fewer than two parts to prune "
                   "(bounded, not moving with time, not a mesh) or more than "
                << ir::kPruneMaxParts << " parts\n";
    }
  }
  choice = chooseRenderSettings(request, &compiled.scene.render);
  if (!quiet) std::cerr << "sdfc: settings: " << choice.reason << "\n";
  // The driver compiles the kernel at its first draw (lavapipe: LLVM, seconds
  // for scenes of instances): a stage of its own, before the passes and their ETA.
  if (!quiet) std::cerr << "sdfc: compiling the kernel (first draw)... " << std::flush;
  const double kernel_seconds = renderer.compileKernel(o.view);
  if (!quiet) std::cerr << "done in " << formatSeconds(kernel_seconds) << "\n";
  timings.add("first draw (driver's kernel compile)", kernel_seconds,
              quick_compile ? "(LLVM unoptimised: a render of few samples)" : "");
  for (size_t f = 0; f < times.size(); ++f) {
    o.time = times[f];
    RenderSettings settings = renderSettingsFor(compiled, o);
    noteNothingToSave();  // this frame's image has no samples yet
    const ProgressCallback terminal = quiet ? ProgressCallback{} : makeTerminalProgress("render");
    const ProgressCallback progress = [terminal](const ProgressInfo& info) {
      if (info.samples_done > 0) noteSamplesTaken();  // worth writing from now on
      if (terminal) terminal(info);
    };
    const bool adaptive = choice.adaptive;
    ImageOptions image_options;
    image_options.denoiser = choice.denoiser;
    image_options.denoise_aovs = cl.denoise_aovs;
    image_options.denoise_select = cl.denoise_select;
    image_options.layers = cl.layers;
    AdaptiveStats adaptive_stats;
    AdaptiveParams params;
    double cost_seconds = 0;
    int cost_code = kExitOk;
    if (adaptive) {
      if (settings.spp % 2 == 1 && settings.spp >= 4)
        std::cerr << "sdfc: warning: --adaptive draws both halves alike: " << settings.spp - 1
                  << " spp mean instead of " << settings.spp << "\n";
      params = adaptiveParamsFrom(cl);
      if (params.time_budget && cl.adaptive_cost == "iterations") {
        const auto cost_start = std::chrono::steady_clock::now();
        cost_code = iterationsCostPass(cl, context, o, settings, cameraFor(compiled.scene),
                                       params.cost_per_sample);
        if (cost_code != kExitOk) return cost_code;
        cost_seconds = secondsSince(cost_start);
      }
      image_options.draw = [&](Renderer& r, const CameraDesc& camera, const RenderSettings& s,
                               SampleHalves* halves, const ProgressCallback& samples) {
        return renderAdaptive(r, camera, s, params, halves, &adaptive_stats, samples, interrupt);
      };
    }
    RenderedImage rendered = renderImage(renderer, compiled, settings, image_options, progress, interrupt);
    settings = rendered.settings;
    RenderOutput& out = rendered.out;
    if (out.interrupted && out.samples_done == 0) {  // an image of no samples replaces no file
      std::cerr << "sdfc: interrupted before any sample; nothing written\n";
      return kExitInterrupted;
    }
    const FloatImage& denoised = rendered.denoised;
    if (adaptive) {
      // bench/adaptive_study.py reads this line.
      if (!quiet && adaptive_stats.first_spp > 0)
        std::cerr << "sdfc: adaptive (" << cl.adaptive_estimate << "): first phase "
                  << adaptive_stats.first_spp << " spp in " << formatSeconds(adaptive_stats.first_seconds)
                  << ", estimate " << formatSeconds(adaptive_stats.estimate_seconds) << ", extra "
                  << adaptive_stats.rounds << " rounds of " << adaptive_stats.draws << " draws in "
                  << formatSeconds(adaptive_stats.extra_seconds) << "; mean " << out.samples_done
                  << " spp, most " << adaptive_stats.max_spp;
      if (!quiet && params.time_budget)
        std::cerr << "; time budget: predicted cost " << adaptive_stats.predicted_cost_ratio
                  << " x uniform's, samples " << adaptive_stats.sample_ratio << " x, cost pass "
                  << formatSeconds(cost_seconds);
      if (!quiet && adaptive_stats.first_spp > 0) std::cerr << "\n";
    }
    // bench/denoise_study.py reads this line: the filter's own cost.
    if (!quiet && !denoised.empty())
      std::cerr << "sdfc: denoised (" << denoiserName(rendered.denoiser) << ") in "
                << std::lround(rendered.denoise_seconds * 1000) << " ms ("
                << std::lround(rendered.denoise_cpu_seconds * 1000) << " CPU ms)\n";
    const std::string frame = times.size() > 1 ? " (frame " + std::to_string(f) + ")" : "";
    timings.add("passes" + frame, out.seconds - out.readback_seconds,
                std::to_string(out.samples_done) + " spp in " + std::to_string(out.passes) + " passes");
    timings.add("readback" + frame, out.readback_seconds, "(staging buffer to the sums and images)");
    if (!denoised.empty()) timings.add("denoise" + frame, rendered.denoise_seconds);
    const FloatImage& image = denoised.empty() ? out.color : denoised;
    const std::string path = frame_numbers.empty() ? cl.output : farm::framePath(cl.output, frame_numbers[f]);
    const auto encode_start = std::chrono::steady_clock::now();
    if (cl.layers) {
      writeExrChannels(path, settings.width, settings.height,
                       renderLayers(compiled, cameraFor(compiled.scene), settings, out));
    } else if (o.view != gpu::kViewBeauty && imageFormatFromPath(path) == ImageFormat::Png) {
      // A debug view's PNG: raw depths and counts mapped into a range a display
      // shows, no tone curve (EXR and PFM keep the raw values; docs/debug_views.md).
      writeImage(path, debugViewForDisplay(o.view, image, debugViewBudget(uint32_t(compiled.emitted.limits.max_steps), settings)),
                 ToneMap{0.0f, ToneCurve::Clamp});
    } else {
      writeImage(path, image, tone);
    }
    timings.add("encoding and writing" + frame, secondsSince(encode_start));
    reportMarchSteps(cl, o.view, out, uint32_t(compiled.emitted.limits.max_steps));
    if (!quiet) {
      // What was done to the samples, and how to have it undone (issue 29); after
      // the parenthesis, which scripts parse (bench/mitsuba_check.py).
      std::string treated;
      if (!denoised.empty())
        treated += std::string(", denoised (") + denoiserName(choice.denoiser) + "; --denoise none for the raw mean)";
      if (imageFormatFromPath(path) == ImageFormat::Png)
        treated += o.view == gpu::kViewBeauty ? std::string(", tone curve ") + toneCurveName(tone.curve)
                   : debugViewNeedsMapping(o.view) ? std::string(", mapped for display (raw values in .exr)")
                                                   : std::string();
      std::cerr << "sdfc: wrote " << path << " (" << out.samples_done << " spp in "
                << formatSeconds(out.seconds) << ", "
                << (out.seconds > 0 ? out.samples_done / out.seconds : 0) << " spp/s)" << treated << "\n";
    }
    if (out.interrupted) {
      std::cerr << "sdfc: interrupted; wrote the " << out.samples_done << " samples accumulated so far"
                << (rendered.denoise_interrupted ? " (in the denoise: their raw mean, undenoised)" : "")
                << "\n";
      return kExitInterrupted;
    }
  }
  return kExitOk;
}

}  // namespace sdfc
