// Progressive headless rendering of a compiled scene shader.
//
//   sdfc::VulkanContext context;
//   sdfc::createContext(context);
//   sdfc::Renderer renderer(context, frag_spirv);   // pipeline creation, timed
//   sdfc::RenderOutput out = renderer.render(camera, settings, sdfc::makeTerminalProgress(),
//                                            sdfc::installInterruptHandler());
//
// A render is a sequence of passes; pass k draws samples [sample_base, sample_base +
// sample_count) of every pixel (FrameParams), and the shader's random numbers depend
// only on (pixel, sample index, seed). The CPU sums pass means weighted by their
// sample counts as exact fixed-point integers (sample_sum.h), so memory does not
// grow with spp, the same settings give bit-identical images, and renders of
// disjoint pass ranges add up to exactly the sums of one render of all of them. Each pass is drawn in full-width bands
// (kBandPixels) with a band-sized target; the AOV attachments, identical in every
// pass, are read back only in the final pass.
#pragma once
#include <atomic>
#include <cstdint>
#include <vector>

#include "camera.h"
#include "camera_inside.h"
#include "denoise_svgf.h"
#include "driver/compile.h"
#include "float_image.h"
#include "progress.h"
#include "render_pipeline.h"
#include "sample_sum.h"
#include "shader_interface.h"
#include "vulkan_context.h"

namespace sdfc::gpu {
// FrameParams::skip_aov_ray: jittered AOVs through specular first hits. Only the
// kernels of scenes with mirror, glass or metal hold it (pathtrace.glsl's
// kAovSpecular), so it lives here rather than in shader_interface.h, which every
// kernel holds verbatim.
inline constexpr uint32_t kAovSpecular = 3;
}  // namespace sdfc::gpu

namespace sdfc {

struct RenderSettings {
  uint32_t width = 640, height = 360;
  uint32_t spp = 16;
  uint32_t max_bounces = 3;
  uint32_t light_samples = 1;
  uint32_t view = gpu::kViewBeauty;  // non-beauty views render one sample in one pass
  uint32_t seed = 0;
  float time = 0;
  // Worst-case loop iterations of one sample (loopIterationsPerSample in
  // runtime/loop_budget.h); 0 = unknown. Passes then take at most
  // (kLavapipeLoopCap - 1 - loop_iterations_per_pass) / this many samples.
  uint32_t loop_iterations_per_sample = 0;
  // Loop iterations of a pass independent of its sample count
  // (loopIterationsPerPassOverhead: the AOV ray).
  uint32_t loop_iterations_per_pass = 0;
  // Instance-hierarchy traversals one scene evaluation may make (the
  // emitter's traversals_per_evaluation); 0 = none. Passes then take fewer samples so each scene
  // evaluation keeps at least kMinTraversalVisits hierarchy visits, and
  // frame.traversal_visits is set from the cap (traversalVisitsWithinCap).
  uint32_t instance_sets = 0;
  // The driver caps loops (VulkanContext::loop_cap; the Renderer sets this from
  // its context). Without a cap a traversal takes every visit it needs.
  bool loop_cap = true;
  // 0 = auto: about kAutoPixelSamplesPerPass pixel-samples per pass, at most 64 spp.
  // Deliberately not timing-based, so pass splits (and thus images) are reproducible.
  uint32_t max_samples_per_pass = 0;
  // Index of the first sample; lets two renders [0,n) and [n,2n) be merged.
  uint32_t first_sample = 0;
  // Also return the exact color sums (RenderOutput::color_sums): what a shard stores.
  bool keep_sums = false;
  // Beauty: AOVs as means over the jittered samples (gpu::kAovJittered) instead
  // of the unjittered AOV ray: RenderOutput's normal_depth and albedo_steps are
  // then sample means (0 where a sample missed) and color's a is the coverage;
  // resolveJitteredAovs turns them into per-hit features for the denoisers.
  bool jittered_aovs = false;
  // With jittered_aovs: where a sample's first hit is specular (mirror, glass,
  // metal of GGX alpha <= 0.1), its features are those of the first
  // non-specular vertex of its path (gpu::kAovSpecular; docs/denoise.md). A
  // kernel without such materials has no specular hits and draws plain jittered AOVs.
  bool specular_aovs = false;
  // false: nothing reads the features (no denoiser): the final pass reads back
  // the colour and attachment 2 (its w, the march steps, feeds `render`'s step
  // statistics) only, and RenderOutput::normal_depth stays empty (0 x 0).
  bool read_features = true;
  double pass_timeout_seconds = 60;
  // Pixels per band (0 = kBandPixels). An interactive view draws its whole
  // window as one band: one submission and one wait a frame instead of several.
  uint64_t band_pixels = 0;
};

constexpr uint64_t kAutoPixelSamplesPerPass = 1u << 20;
constexpr uint32_t kAutoMaxSamplesPerPass = 64;
// Hierarchy visits per evaluation a pass aims to allow (passes shrink to one
// sample for it), and the most it grants (a bound on one evaluation's work).
constexpr uint32_t kMinTraversalVisits = 48;
constexpr uint32_t kMaxTraversalVisits = 256;
// frame.traversal_visits on a driver without the loop cap: never reached (a
// traversal ends when its stack is empty, after at most 2 visits per node), so
// every set is evaluated exactly.
constexpr uint32_t kUncappedTraversalVisits = 1u << 30;
// frame.traversal_visits for a pass of `sample_count` samples under `settings`.
uint32_t traversalVisitsFor(const RenderSettings& settings, uint32_t sample_count);
// render() draws full-width bands of about this many pixels (at least one row), so
// its device images and staging buffer do not grow with the output size.
constexpr uint64_t kBandPixels = 1u << 17;

// Samples per pass the renderer uses for `settings` (>= 1).
uint32_t chooseSamplesPerPass(const RenderSettings& settings);

struct RenderOutput {
  FloatImage color;         // mean radiance (beauty) or the debug view value, a = 1
  FloatImage normal_depth;  // attachment 1 (the same in every pass; read back once)
  FloatImage albedo_steps;  // attachment 2 (the same in every pass; read back once)
  // With RenderSettings::keep_sums: the exact sum over samples of each pixel's r, g, b, a
  // (4 per pixel, row-major); color = sampleMean(sum, samples_done).
  std::vector<SampleSum> color_sums;
  uint32_t samples_done = 0;  // per pixel; with sample_counts, their mean
  // Adaptive sampling (adaptive.h): each pixel's own sample count (row-major);
  // empty when every pixel took samples_done.
  std::vector<uint32_t> sample_counts;
  uint32_t passes = 0;
  uint32_t samples_per_pass = 0;
  double seconds = 0;           // wall time of render()
  double pipeline_seconds = 0;  // pipeline creation of this renderer
  // Of `seconds`: the CPU's share after each pass, reading the staging buffer
  // into the sums and the output images (--timings' readback).
  double readback_seconds = 0;
  bool interrupted = false;
};

// An image being accumulated pass by pass: the state render() keeps between passes,
// exposed so an interactive view can draw a pass per frame and show the mean so far
// (Renderer::startAccumulation, addPass). Sums are per band and exact.
struct Accumulation {
  uint32_t width = 0, height = 0;
  uint32_t band_rows = 0, band_count = 0;
  RenderSettings settings;    // what it was started with (first sample, timeouts, sums)
  gpu::FrameParams params{};  // camera and settings; sample_base/count set per pass
  uint32_t samples_done = 0;
  uint32_t passes = 0;
  // Per band: exact sums of pass mean * pass samples (sample_sum.h), so any pass split
  // of the same samples gives the same bits.
  std::vector<std::vector<SampleSum>> sums;
  // Per band: the first pass's means as they came, while it is the only pass;
  // the sums are formed when a second pass arrives. A one-pass image (every
  // debug view, the first frame after each change in `sdfc view`) then costs
  // no fixed-point arithmetic, and mean() returns the same floats.
  std::vector<std::vector<float>> first_pass;
  uint32_t first_pass_samples = 0;
  // Attachments 1 and 2 (the unjittered primary ray: the same in every pass). With
  // keep_aovs the first pass reads them back; render() reads them in its final pass.
  bool keep_aovs = false;
  FloatImage normal_depth, albedo_steps;
  double readback_seconds = 0;  // RenderOutput::readback_seconds so far

  // Mean colour of the samples so far (zeros before the first pass). Exactly what
  // render() returns for the same samples and pass split.
  FloatImage mean() const;
  // The same into `out`, reusing its storage (a frame loop's per-frame image).
  void meanInto(FloatImage& out) const;
  // The same into width * height * 4 floats at `rgba` (the view's display pass input).
  void meanInto(float* rgba) const;
};

// Sample-weighted mean of two renders of the same size (e.g. samples [0,n) and
// [n,m)). With color_sums in both (keep_sums), exactly equal to one render of both
// sample ranges when their passes split the samples the same way; otherwise a
// double-precision weighted mean of the float images.
RenderOutput mergeRenders(const RenderOutput& a, const RenderOutput& b);

class Renderer {
 public:
  // Builds the pipeline for `frag_spirv` (a fragment shader following
  // shader_interface.h). The context must outlive the renderer.
  // `scene_data` (vec4s) is bound as the storage buffer at set 0, binding 0
  // when not empty (the emitter's EmitResult::scene_data).
  Renderer(const VulkanContext& context, const std::vector<uint32_t>& frag_spirv,
           const std::vector<float>& scene_data = {});
  // A compiled scene's kernel, its scene data and its camera-inside test (the
  // test reads `compiled.scene`, so `compiled` must outlive the renderer).
  Renderer(const VulkanContext& context, const CompiledScene& compiled);
  // The driver caps loops (VulkanContext::loop_cap): hierarchy visits are rationed.
  bool loopCap() const { return context_.loop_cap; }
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  double pipelineSeconds() const { return pipeline_.create_seconds; }

  // Draws one pixel of `view` once, so that the driver compiles the kernel now:
  // lavapipe compiles a pipeline's fragment shader with LLVM at its first draw,
  // which on a scene of instances takes seconds. `render` shows it as a stage of
  // its own, outside the ETA; `sdfc view` runs it on its worker thread, off the
  // frame loop. `pool`: the calling thread's command pool (null: the context's).
  // Returns its wall seconds (also kernelCompileSeconds()).
  double compileKernel(uint32_t view, VkCommandPool pool = VK_NULL_HANDLE);
  double kernelCompileSeconds() const { return kernel_compile_seconds_; }

  // FrameParams::skip_aov_ray of a pass that records jittered AOVs under
  // `settings`: kAovSpecular when asked for and the kernel has it, else kAovJittered.
  uint32_t jitteredAovMode(const RenderSettings& settings) const {
    return settings.specular_aovs && specular_kernel_ ? gpu::kAovSpecular : gpu::kAovJittered;
  }

  // Decides FrameParams::camera_inside for each accumulation (its camera and time);
  // pinhole kernels read it instead of testing the scene per pixel. Without one the
  // camera is taken as outside.
  void setCameraInsideTest(CameraInsideTest test) { inside_test_ = std::move(test); }

  // Throws RuntimeError on device errors or a pass exceeding its timeout. When
  // `*interrupt` becomes true, stops after the current pass and returns what was
  // accumulated with interrupted = true.
  RenderOutput render(const CameraDesc& camera, const RenderSettings& settings,
                      const ProgressCallback& progress = {},
                      const std::atomic<bool>* interrupt = nullptr);

  // The shared progressive core: render() is startAccumulation + addPass until the
  // last pass (which it resolves band by band to bound memory); `sdfc view` calls
  // addPass once a frame and shows Accumulation::mean().
  Accumulation startAccumulation(const CameraDesc& camera, const RenderSettings& settings,
                                 bool keep_aovs);
  // Draws `count` more samples of every pixel into `acc` (non-final: sums only).
  void addPass(Accumulation& acc, uint32_t count);

  // One pass of several scissored draws, each with its own push constants, over the
  // top `rows` rows of a width x target_rows target (kept between passes; adaptive.cpp:
  // per-block sample counts). Returns the readback: the `readback` attachments (kRead*),
  // targetImageFloats() apart, each packed width x rows; valid until the next pass.
  const float* runDraws(uint32_t width, uint32_t target_rows, uint32_t rows,
                        const std::vector<PassDraw>& draws, double timeout_seconds,
                        uint32_t readback);
  size_t targetImageFloats() const { return target_.floatsPerImage(); }

  // One raw pass with explicit push constants; fills the three attachments.
  void renderPass(const gpu::FrameParams& params, double timeout_seconds, FloatImage& color,
                  FloatImage& normal_depth, FloatImage& albedo_steps);

 private:
  void ensureTarget(uint32_t width, uint32_t height);
  // Draws band b of `acc` with `count` samples. Without `final_out` the band's colour
  // is added to its sums; with it the sums become the band's output floats (and the
  // AOVs are read back), then are freed.
  void drawBand(Accumulation& acc, uint32_t b, uint32_t count, RenderOutput* final_out);

  const VulkanContext& context_;
  RenderPipeline pipeline_;
  RenderTarget target_;
  CameraInsideTest inside_test_;
  bool specular_kernel_ = false;  // the kernel holds kAovSpecular (jitteredAovMode)
  double kernel_compile_seconds_ = 0;
};

// A render with RenderSettings::jittered_aovs -> the denoisers' features:
// normal, albedo and distance as means over the samples that hit (distance -1
// where fewer than half hit, the sky side of the filters), steps the mean over
// all samples; color's a back to 1. Also the halves' a, if given.
void resolveJitteredAovs(RenderOutput& out, SampleHalves* halves = nullptr);

// Renders samples [first, first + n/2) and [first + n/2, first + n) of `settings`
// as two independent halves and returns their merge (the same estimator as one
// render of n samples), the halves themselves in `*halves`: the per-pixel noise
// estimate of the variance-guided denoiser, for the cost of one more primary AOV
// ray per pixel. With fewer than 2 samples, or when interrupted in the first
// half, `halves->samples_b` is 0.
RenderOutput renderHalves(Renderer& renderer, const CameraDesc& camera,
                          const RenderSettings& settings, SampleHalves* halves,
                          const ProgressCallback& progress = {},
                          const std::atomic<bool>* interrupt = nullptr);

}  // namespace sdfc
