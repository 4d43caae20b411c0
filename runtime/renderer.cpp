#include "renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <future>

#include "loop_budget.h"
#include "vk_check.h"

namespace sdfc {
namespace {

using Clock = std::chrono::steady_clock;

void copyImage(const float* source, uint32_t width, uint32_t height, FloatImage& out) {
  out.width = width;
  out.height = height;
  out.rgba.assign(source, source + size_t(width) * height * 4);
}

}  // namespace

uint32_t chooseSamplesPerPass(const RenderSettings& settings) {
  if (settings.view != gpu::kViewBeauty) return 1;
  uint32_t limit = settings.max_samples_per_pass;
  if (limit == 0) {
    const uint64_t pixels = std::max<uint64_t>(1, uint64_t(settings.width) * settings.height);
    limit = static_cast<uint32_t>(
        std::clamp<uint64_t>(kAutoPixelSamplesPerPass / pixels, 1, kAutoMaxSamplesPerPass));
  }
  if (settings.instance_sets > 0 && settings.loop_iterations_per_sample > 0) {
    // Fewer samples per pass leave more of the cap to hierarchy visits.
    while (limit > 1 && traversalVisitsFor(settings, limit) < kMinTraversalVisits) limit /= 2;
  }
  if (settings.loop_iterations_per_sample > 0) {
    // Strictly below the cap, as loop_budget.h's samplesPerPassWithinCap.
    const uint64_t room = gpu::kLavapipeLoopCap - 1 -
                          std::min<uint64_t>(settings.loop_iterations_per_pass,
                                             gpu::kLavapipeLoopCap - 1);
    const uint32_t loop_limit = uint32_t(room / settings.loop_iterations_per_sample);
    limit = std::min(limit, std::max<uint32_t>(loop_limit, 1));
  }
  return std::max<uint32_t>(1, std::min(limit, std::max<uint32_t>(settings.spp, 1)));
}

uint32_t traversalVisitsFor(const RenderSettings& settings, uint32_t sample_count) {
  if (settings.instance_sets == 0) return 0;
  if (!settings.loop_cap) return kUncappedTraversalVisits;
  if (settings.loop_iterations_per_sample == 0) return kMinTraversalVisits;  // unknown kernel
  const uint64_t kernel = uint64_t(settings.loop_iterations_per_pass) +
                          uint64_t(sample_count) * settings.loop_iterations_per_sample;
  return std::min(kMaxTraversalVisits,
                  traversalVisitsWithinCap(kernel, sample_count, settings.instance_sets));
}

RenderOutput mergeRenders(const RenderOutput& a, const RenderOutput& b) {
  if (a.color.width != b.color.width || a.color.height != b.color.height)
    throw RuntimeError("mergeRenders: image sizes differ");
  RenderOutput out = a;
  out.samples_done = a.samples_done + b.samples_done;
  out.passes = a.passes + b.passes;
  out.seconds = a.seconds + b.seconds;
  out.readback_seconds = a.readback_seconds + b.readback_seconds;
  out.interrupted = a.interrupted || b.interrupted;
  if (out.samples_done == 0) return out;
  if (!a.color_sums.empty() && a.color_sums.size() == b.color_sums.size()) {
    const size_t pixels = out.color.pixelCount();
    for (size_t i = 0; i < pixels * 4; ++i) {
      out.color_sums[i] = a.color_sums[i] + b.color_sums[i];
      out.color.rgba[i] = sampleMean(out.color_sums[i], out.samples_done);
    }
    return out;
  }
  out.color_sums.clear();
  const double wa = a.samples_done, wb = b.samples_done, total = out.samples_done;
  auto merge = [&](const FloatImage& x, const FloatImage& y, FloatImage& result) {
    for (size_t i = 0; i < result.rgba.size(); ++i)
      result.rgba[i] = static_cast<float>((double(x.rgba[i]) * wa + double(y.rgba[i]) * wb) / total);
  };
  merge(a.color, b.color, out.color);
  merge(a.normal_depth, b.normal_depth, out.normal_depth);
  merge(a.albedo_steps, b.albedo_steps, out.albedo_steps);
  return out;
}

Renderer::Renderer(const VulkanContext& context, const std::vector<uint32_t>& frag_spirv,
                   const std::vector<float>& scene_data)
    : context_(context) {
  // The attachments' first image view compiles in lavapipe beside the pipeline
  // (render_pipeline.h): the second core is idle otherwise. Joined before returning.
  std::future<void> views = std::async(std::launch::async, [&] { warmAttachmentViews(context_); });
  createRenderPipeline(pipeline_, context_, frag_spirv, scene_data);
}

Renderer::Renderer(const VulkanContext& context, const CompiledScene& compiled)
    : Renderer(context, compiled.spirv, compiled.emitted.scene_data) {
  inside_test_ = cameraInsideTest(compiled.scene, compiled.emitted.limits);
  // pathtrace.glsl keeps kAovSpecular in path-tracing kernels with a specular material.
  const std::set<std::string>& f = compiled.emitted.stats.features;
  specular_kernel_ = f.count("SDFC_TRACE") &&
                     (f.count("SDFC_HAS_MIRROR") || f.count("SDFC_HAS_GLASS") || f.count("SDFC_HAS_METAL"));
}

double Renderer::compileKernel(uint32_t view, VkCommandPool pool) {
  const auto start = Clock::now();
  RenderTarget pixel;
  createRenderTarget(pixel, context_, pipeline_, 1, 1, pool);
  try {
    CameraDesc camera;
    gpu::FrameParams params = makeFrameParams(camera, 1, 1, 0.0f);
    params.view = view;
    params.sample_count = 1;
    params.traversal_visits = kMinTraversalVisits;
    runPass(context_, pipeline_, pixel, &params, 600.0, 1, kReadColor);
  } catch (...) {
    destroyRenderTarget(pixel, context_);
    throw;
  }
  destroyRenderTarget(pixel, context_);
  kernel_compile_seconds_ = secondsSince(start);
  return kernel_compile_seconds_;
}

Renderer::~Renderer() {
  destroyRenderTarget(target_, context_);
  destroyRenderPipeline(pipeline_, context_);
}

void Renderer::ensureTarget(uint32_t width, uint32_t height) {
  if (target_.framebuffer && target_.width == width && target_.height == height) return;
  destroyRenderTarget(target_, context_);
  createRenderTarget(target_, context_, pipeline_, width, height);
}

void Renderer::renderPass(const gpu::FrameParams& params, double timeout_seconds,
                          FloatImage& color, FloatImage& normal_depth, FloatImage& albedo_steps) {
  ensureTarget(params.width, params.height);
  runPass(context_, pipeline_, target_, &params, timeout_seconds);
  const size_t n = target_.floatsPerImage();
  copyImage(target_.mapped, params.width, params.height, color);
  copyImage(target_.mapped + n, params.width, params.height, normal_depth);
  copyImage(target_.mapped + 2 * n, params.width, params.height, albedo_steps);
}

const float* Renderer::runDraws(uint32_t width, uint32_t target_rows, uint32_t rows,
                                const std::vector<PassDraw>& draws, double timeout_seconds,
                                uint32_t readback) {
  ensureTarget(width, target_rows);
  runPass(context_, pipeline_, target_, draws.data(), draws.size(), timeout_seconds, rows, readback);
  return target_.mapped;
}

FloatImage Accumulation::mean() const {
  FloatImage out;
  meanInto(out);
  return out;
}

void Accumulation::meanInto(FloatImage& out) const {
  out.width = width;
  out.height = height;
  out.rgba.resize(size_t(width) * height * 4);
  meanInto(out.rgba.data());
}

void Accumulation::meanInto(float* rgba) const {
  if (samples_done == 0) {
    std::fill(rgba, rgba + size_t(width) * height * 4, 0.0f);
    return;
  }
  for (uint32_t b = 0; b < band_count; ++b) {
    float* color = rgba + size_t(b) * band_rows * width * 4;
    if (b < first_pass.size() && !first_pass[b].empty()) {
      const std::vector<float>& pass = first_pass[b];
      for (size_t i = 0; i < pass.size(); ++i) color[i] = onePassMean(pass[i], first_pass_samples);
      continue;
    }
    const std::vector<SampleSum>& sum = sums[b];
    // sampleMean: the same floats as render()'s final pass for the same samples.
    for (size_t i = 0; i < sum.size(); ++i) color[i] = sampleMean(sum[i], samples_done);
  }
}

Accumulation Renderer::startAccumulation(const CameraDesc& camera, const RenderSettings& settings,
                                         bool keep_aovs) {
  Accumulation acc;
  // The image is drawn in full-width bands of about kBandPixels pixels with a band-sized
  // target, so device images and staging stay small whatever the output size.
  acc.width = settings.width;
  acc.height = settings.height;
  const uint64_t band_pixels = settings.band_pixels > 0 ? settings.band_pixels : kBandPixels;
  acc.band_rows = std::clamp<uint32_t>(uint32_t(band_pixels / std::max<uint32_t>(acc.width, 1)), 1,
                                       std::max<uint32_t>(acc.height, 1));
  acc.band_count = (acc.height + acc.band_rows - 1) / std::max<uint32_t>(acc.band_rows, 1);
  acc.settings = settings;
  acc.settings.loop_cap = context_.loop_cap;
  acc.params = makeFrameParams(camera, acc.width, acc.height, settings.time);
  acc.params.seed = settings.seed;
  acc.params.view = settings.view;
  acc.params.max_bounces = settings.max_bounces;
  acc.params.light_samples = settings.light_samples;
  acc.params.camera_inside = inside_test_ && inside_test_(camera.position, settings.time) ? 1u : 0u;
  acc.sums.resize(acc.band_count);
  acc.first_pass.resize(acc.band_count);
  acc.keep_aovs = keep_aovs;
  if (keep_aovs) {
    acc.normal_depth = FloatImage(acc.width, acc.height);
    acc.albedo_steps = FloatImage(acc.width, acc.height);
  }
  return acc;
}

void Renderer::drawBand(Accumulation& acc, uint32_t b, uint32_t count, RenderOutput* final_out) {
  const uint32_t width = acc.width;
  const uint32_t y0 = b * acc.band_rows, rows = std::min(acc.band_rows, acc.height - y0);
  const bool keep_sums = acc.settings.keep_sums;
  gpu::FrameParams& params = acc.params;
  params.tile_x = 0;
  params.tile_y = y0;
  params.sample_count = count;
  params.traversal_visits = traversalVisitsFor(acc.settings, count);
  const bool beauty = acc.settings.view == gpu::kViewBeauty;
  // Jittered AOVs differ every pass: each pass's are read and summed.
  const bool jittered = acc.settings.jittered_aovs && beauty;
  const bool read_aovs = final_out || (acc.keep_aovs && acc.passes == 0) || jittered;
  // Beauty passes whose AOVs are not read skip the AOV ray (the image is the same).
  params.skip_aov_ray = jittered ? jitteredAovMode(acc.settings) : !read_aovs && count > 0 && beauty;
  // A render nothing reads the features of: the colour and the march steps
  // (attachment 2's w) only.
  const bool features = acc.settings.read_features;
  runPass(context_, pipeline_, target_, &params, acc.settings.pass_timeout_seconds, rows,
          !read_aovs ? kReadColor : features ? kReadAll : kReadColor | kReadAlbedoSteps);
  // Everything below reads the staging buffer: --timings' readback.
  struct ReadbackClock {
    double& total;
    Clock::time_point start = Clock::now();
    ~ReadbackClock() { total += secondsSince(start); }
  } readback_clock{acc.readback_seconds};
  const size_t band_floats = size_t(width) * rows * 4;
  const size_t band_base = size_t(y0) * width * 4;  // the band's first float in a whole image
  const float* pass = target_.mapped;
  const float* normal_depth = target_.mapped + target_.floatsPerImage();
  const float* albedo_steps = normal_depth + target_.floatsPerImage();
  std::vector<SampleSum>& sum = acc.sums[b];
  std::vector<float>& first = acc.first_pass[b];
  if (!final_out && acc.samples_done == 0 && count > 0 && !keep_sums) {
    // The only pass so far: keep its floats (see Accumulation::first_pass).
    first.assign(pass, pass + band_floats);
  } else {
    if (sum.empty() && (!final_out || keep_sums || !first.empty())) {
      sum.assign(band_floats, 0);
      for (size_t i = 0; i < first.size(); ++i) sum[i] = sampleTerm(first[i], acc.first_pass_samples);
      std::vector<float>().swap(first);
    }
    if (count > 0 && !sum.empty())
      for (size_t i = 0; i < band_floats; ++i) sum[i] += sampleTerm(pass[i], count);
  }
  if (jittered) {
    // Running sums of pass mean * pass samples, in acc's AOV images.
    if (acc.albedo_steps.empty()) {
      if (features) acc.normal_depth = FloatImage(acc.width, acc.height);
      acc.albedo_steps = FloatImage(acc.width, acc.height);
    }
    float* as_sum = acc.albedo_steps.rgba.data() + band_base;
    for (size_t i = 0; count > 0 && i < band_floats; ++i) as_sum[i] += albedo_steps[i] * float(count);
    float* nd_sum = features ? acc.normal_depth.rgba.data() + band_base : nullptr;
    for (size_t i = 0; count > 0 && features && i < band_floats; ++i) nd_sum[i] += normal_depth[i] * float(count);
    if (!final_out) return;
  }
  if (!final_out) {
    if (read_aovs) {
      for (size_t i = 0; i < band_floats; ++i) {
        acc.normal_depth.rgba[band_base + i] = normal_depth[i] + 0.0f;
        acc.albedo_steps.rgba[band_base + i] = albedo_steps[i] + 0.0f;
      }
    }
    return;
  }
  RenderOutput& out = *final_out;
  // count_done >= 1: a zero-sample final pass only follows completed passes.
  const uint32_t count_done = acc.samples_done + count;
  // resize() value-initializes only the new band: pages are touched as written.
  auto grow = [band_floats](FloatImage& image) {
    const size_t base = image.rgba.size();
    image.rgba.resize(base + band_floats);
    return image.rgba.data() + base;
  };
  float* color = grow(out.color);
  if (sum.empty() && count_done == count) {
    // A one-pass render never filled `sum`: its term is the whole sum, and its
    // mean the pass's float (onePassMean: the same bits, without the 128-bit division).
    for (size_t i = 0; i < band_floats; ++i) color[i] = onePassMean(pass[i], count);
  } else {
    for (size_t i = 0; i < band_floats; ++i)
      color[i] = sampleMean(sum.empty() ? sampleTerm(pass[i], count) : sum[i], count_done);
  }
  if (keep_sums) out.color_sums.insert(out.color_sums.end(), sum.begin(), sum.end());
  std::vector<SampleSum>().swap(sum);
  // + 0.0f maps -0 to +0, as the former double accumulation (0.0 + x) did.
  float* as = grow(out.albedo_steps);
  float* nd = features ? grow(out.normal_depth) : nullptr;
  if (jittered) {
    const float scale = 1.0f / float(count_done);
    for (size_t i = 0; i < band_floats; ++i) as[i] = acc.albedo_steps.rgba[band_base + i] * scale;
    for (size_t i = 0; features && i < band_floats; ++i) nd[i] = acc.normal_depth.rgba[band_base + i] * scale;
    return;
  }
  for (size_t i = 0; i < band_floats; ++i) as[i] = albedo_steps[i] + 0.0f;
  for (size_t i = 0; features && i < band_floats; ++i) nd[i] = normal_depth[i] + 0.0f;
}

void Renderer::addPass(Accumulation& acc, uint32_t count) {
  ensureTarget(acc.width, acc.band_rows);
  acc.params.sample_base = acc.settings.first_sample + acc.samples_done;
  for (uint32_t b = 0; b < acc.band_count; ++b) drawBand(acc, b, count, nullptr);
  if (acc.samples_done == 0) acc.first_pass_samples = count;
  acc.samples_done += count;
  ++acc.passes;
}

RenderOutput Renderer::render(const CameraDesc& camera, const RenderSettings& settings,
                              const ProgressCallback& progress,
                              const std::atomic<bool>* interrupt) {
  const auto start = Clock::now();
  const bool beauty = settings.view == gpu::kViewBeauty;
  const uint32_t total = beauty ? std::max<uint32_t>(settings.spp, 1) : 1;
  const uint32_t per_pass = chooseSamplesPerPass(settings);
  if (settings.loop_iterations_per_sample > 0 &&
      uint64_t(settings.loop_iterations_per_sample) + settings.loop_iterations_per_pass >=
          gpu::kLavapipeLoopCap)
    std::fprintf(stderr,
                 "sdfc: warning: a one-sample pass may take %u + %u loop iterations, not below "
                 "lavapipe's cap of %u; some pixels may be cut short\n",
                 settings.loop_iterations_per_sample, settings.loop_iterations_per_pass,
                 gpu::kLavapipeLoopCap);
  RenderSettings on_this_driver = settings;
  on_this_driver.loop_cap = context_.loop_cap;
  if (settings.instance_sets > 0 && traversalVisitsFor(on_this_driver, 1) < 8)
    std::fprintf(stderr,
                 "sdfc: warning: this driver's loop cap leaves %u hierarchy visits per scene "
                 "evaluation: instances may be marched slowly and parts thinner than a pixel "
                 "missed (fewer bounces or steps help; Mesa 25's lavapipe, tools/lavapipe25.sh, "
                 "has no cap)\n",
                 traversalVisitsFor(on_this_driver, 1));

  Accumulation acc = startAccumulation(camera, settings, false);
  const uint32_t width = acc.width, height = acc.height;
  ensureTarget(width, acc.band_rows);

  RenderOutput out;
  out.pipeline_seconds = pipeline_.create_seconds;
  out.samples_per_pass = per_pass;
  const size_t n = size_t(width) * height * 4;
  // The outputs are appended band by band in the final pass: reserving without
  // zero-filling keeps their pages untouched until written, while the band sums
  // they replace are freed.
  out.color.width = out.normal_depth.width = out.albedo_steps.width = width;
  out.color.height = out.normal_depth.height = out.albedo_steps.height = height;
  out.color.rgba.reserve(n);
  if (settings.read_features || (settings.jittered_aovs && beauty))
    out.normal_depth.rgba.reserve(n);
  else
    out.normal_depth = FloatImage();  // RenderSettings::read_features
  out.albedo_steps.rgba.reserve(n);
  if (settings.keep_sums) out.color_sums.reserve(n);

  // The final pass (or a zero-sample one after an interrupt) resolves the sums.
  auto finalPass = [&](uint32_t count) {
    acc.params.sample_base = acc.settings.first_sample + acc.samples_done;
    for (uint32_t b = 0; b < acc.band_count; ++b) drawBand(acc, b, count, &out);
    acc.samples_done += count;
    if (count > 0) ++acc.passes;
  };

  while (acc.samples_done < total) {
    if (interrupt && interrupt->load()) {
      out.interrupted = true;
      break;
    }
    const uint32_t count = std::min(per_pass, total - acc.samples_done);
    if (acc.samples_done + count == total)
      finalPass(count);
    else
      addPass(acc, count);

    if (progress && acc.samples_done < total) {
      ProgressInfo info;
      info.samples_done = acc.samples_done;
      info.samples_total = total;
      info.passes_done = acc.passes;
      info.elapsed_seconds = secondsSince(start);
      info.eta_seconds = info.elapsed_seconds / acc.samples_done * (total - acc.samples_done);
      progress(info);
    }
  }
  if (out.interrupted) {
    if (acc.samples_done == 0) {
      // Nothing rendered: zero images, as before any pass.
      out.color = FloatImage(width, height);
      out.normal_depth = FloatImage(width, height);
      out.albedo_steps = FloatImage(width, height);
    } else {
      // The AOVs were not read back yet: a zero-sample pass traces only the primary
      // ray (the same values as any pass) while the sums become the mean.
      finalPass(0);
    }
  }
  out.samples_done = acc.samples_done;
  out.passes = acc.passes;
  out.seconds = secondsSince(start);
  out.readback_seconds = acc.readback_seconds;
  reportFinished(progress, out.samples_done, total, out.passes, out.seconds);
  return out;
}

void resolveJitteredAovs(RenderOutput& out, SampleHalves* halves) {
  const bool features = !out.normal_depth.empty();  // RenderSettings::read_features
  for (size_t i = 0; i < out.color.pixelCount(); ++i) {
    float& coverage = out.color.rgba[i * 4 + 3];
    float* as = &out.albedo_steps.rgba[i * 4];
    const float inverse = coverage > 0.0f ? 1.0f / coverage : 0.0f;
    for (int c = 0; c < 3; ++c) as[c] *= inverse;
    if (features) {
      float* nd = &out.normal_depth.rgba[i * 4];
      for (int c = 0; c < 3; ++c) nd[c] *= inverse;
      nd[3] = coverage >= 0.5f ? nd[3] * inverse : -1.0f;
    }
    coverage = 1.0f;
  }
  if (halves)
    for (FloatImage* half : {&halves->a, &halves->b})
      for (size_t i = 0; i < half->pixelCount(); ++i) half->rgba[i * 4 + 3] = 1.0f;
}

RenderOutput renderHalves(Renderer& renderer, const CameraDesc& camera,
                          const RenderSettings& settings, SampleHalves* halves,
                          const ProgressCallback& progress,
                          const std::atomic<bool>* interrupt) {
  *halves = SampleHalves();
  if (settings.view != gpu::kViewBeauty || settings.spp < 2)
    return renderer.render(camera, settings, progress, interrupt);
  RenderSettings first = settings;
  first.spp = settings.spp / 2;
  RenderOutput a = renderer.render(camera, first, progress, interrupt);
  if (a.interrupted) return a;
  RenderSettings second = settings;
  second.spp = settings.spp - first.spp;
  second.first_sample = settings.first_sample + first.spp;
  RenderOutput b = renderer.render(camera, second, progress, interrupt);
  if (b.samples_done == 0) return a;
  RenderOutput merged = mergeRenders(a, b);
  halves->a = std::move(a.color);
  halves->b = std::move(b.color);
  halves->samples_a = a.samples_done;
  halves->samples_b = b.samples_done;
  return merged;
}

}  // namespace sdfc
