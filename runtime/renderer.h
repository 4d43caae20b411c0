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
// sample counts in double, in pass order, so memory does not grow with spp and the
// same settings give bit-identical images. Each pass is drawn in full-width bands
// (kBandPixels) with a band-sized target; the AOV attachments, identical in every
// pass, are read back only in the final pass.
#pragma once
#include <atomic>
#include <cstdint>
#include <vector>

#include "camera.h"
#include "denoise_svgf.h"
#include "float_image.h"
#include "progress.h"
#include "render_pipeline.h"
#include "shader_interface.h"
#include "vulkan_context.h"

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
  // 0 = auto: about kAutoPixelSamplesPerPass pixel-samples per pass, at most 64 spp.
  // Deliberately not timing-based, so pass splits (and thus images) are reproducible.
  uint32_t max_samples_per_pass = 0;
  // Index of the first sample; lets two renders [0,n) and [n,2n) be merged.
  uint32_t first_sample = 0;
  double pass_timeout_seconds = 60;
};

constexpr uint64_t kAutoPixelSamplesPerPass = 1u << 20;
constexpr uint32_t kAutoMaxSamplesPerPass = 64;
// render() draws full-width bands of about this many pixels (at least one row), so
// its device images and staging buffer do not grow with the output size.
constexpr uint64_t kBandPixels = 1u << 17;

// Samples per pass the renderer uses for `settings` (>= 1).
uint32_t chooseSamplesPerPass(const RenderSettings& settings);

struct RenderOutput {
  FloatImage color;         // mean radiance (beauty) or the debug view value, a = 1
  FloatImage normal_depth;  // attachment 1 (the same in every pass; read back once)
  FloatImage albedo_steps;  // attachment 2 (the same in every pass; read back once)
  uint32_t samples_done = 0;
  uint32_t passes = 0;
  uint32_t samples_per_pass = 0;
  double seconds = 0;           // wall time of render()
  double pipeline_seconds = 0;  // pipeline creation of this renderer
  bool interrupted = false;
};

// Sample-weighted mean of two renders of the same size (e.g. samples [0,n) and
// [n,m)), computed in double. Exactly equal to one render of both sample ranges
// when each input was a single pass with the same split.
RenderOutput mergeRenders(const RenderOutput& a, const RenderOutput& b);

class Renderer {
 public:
  // Builds the pipeline for `frag_spirv` (a fragment shader following
  // shader_interface.h). The context must outlive the renderer.
  Renderer(const VulkanContext& context, const std::vector<uint32_t>& frag_spirv);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  double pipelineSeconds() const { return pipeline_.create_seconds; }

  // Throws RuntimeError on device errors or a pass exceeding its timeout. When
  // `*interrupt` becomes true, stops after the current pass and returns what was
  // accumulated with interrupted = true.
  RenderOutput render(const CameraDesc& camera, const RenderSettings& settings,
                      const ProgressCallback& progress = {},
                      const std::atomic<bool>* interrupt = nullptr);

  // One raw pass with explicit push constants; fills the three attachments.
  void renderPass(const gpu::FrameParams& params, double timeout_seconds, FloatImage& color,
                  FloatImage& normal_depth, FloatImage& albedo_steps);

 private:
  void ensureTarget(uint32_t width, uint32_t height);

  const VulkanContext& context_;
  RenderPipeline pipeline_;
  RenderTarget target_;
};

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
