// Adaptive sampling at a fixed mean budget (`sdfc render --adaptive`, issue 13).
//
// A first phase draws a uniform share of the requested samples as the two
// independent halves the denoisers use. Each pixel's error is then estimated
// from them (AdaptiveEstimate), and the rest of the budget is handed out per
// block of pixels in proportion to a power of the estimate, at most `cap` times
// the first phase per pixel, so that the counts sum to exactly spp x pixels:
// "16 spp" means 16 samples per pixel on average (with time_budget: the uniform
// 16 spp render's predicted cost instead). The extra samples go to both
// halves alike (each pixel's halves keep equal counts, so the denoisers'
// variance from the halves stays valid) and continue each pixel's own sample
// sequence after the first phase's indices: no random number is reused.
//
// Per-pixel counts need no kernel change: a pass is a set of scissored draws,
// one per rectangle of equal count, each with its own sample range in the push
// constants (runPass with PassDraw). Counts are per block (lavapipe shades 8
// lanes in lockstep and rasterises in tiles: a block drawn at one count costs
// what its slowest pixel costs anyway). Sums stay exact fixed point
// (sample_sum.h), each pixel divided by its own count.
//
// Bias: the counts are chosen from the first phase's samples, which stay in the
// estimate, so a pixel whose first samples came out noisy gets more samples and
// the first phase's weight in its mean is smaller. This correlation vanishes as
// the first phase grows (its error estimate converges) and is zero for a
// uniform allocation (docs/adaptive.md).
#pragma once
#include <atomic>
#include <optional>
#include <string_view>
#include <vector>

#include "renderer.h"

namespace sdfc {

enum class AdaptiveEstimate {
  Uniform,   // every pixel the same extra count: the non-adaptive render, bit for bit
  Variance,  // the halves' relative squared difference (the variance of the mean)
  Denoised,  // nlr's filtered half against the other half (denoise_select.h's estimate)
  Display,   // the halves' squared difference as displayed (clamped to [0, 1], sRGB): FLIP's view
};

std::optional<AdaptiveEstimate> parseAdaptiveEstimate(std::string_view name);
const char* adaptiveEstimateName(AdaptiveEstimate estimate);

struct AdaptiveParams {
  // Of the requested spp, drawn uniformly first (castle, colonnade, glass Menger,
  // 16 spp: 0.25 of 0.125, 0.25, 0.375, 0.5, 0.75; docs/adaptive.md).
  float first_share = 0.25f;
  // A pixel's total samples at most cap x the first phase's (8 of 4, 8, 16, 32:
  // larger caps chase the glass Menger's caustic fireflies).
  float cap = 8.0f;
  uint32_t block = 8;        // counts per block x block pixels
  // Extra samples proportional to estimate^power: 0.5 minimises the summed error
  // when each pixel's error falls as 1/samples (Lagrange: n_p ~ sqrt(e_p)).
  float power = 0.5f;
  int box_radius = 2;  // estimates box-averaged over (2r+1)^2 (one pixel's is as noisy as a sample)
  // Variance: as good as Denoised at share 0.25 on the three scenes, without
  // Denoised's extra filter run (nlr's 2.3 CPU s at 640x360).
  AdaptiveEstimate estimate = AdaptiveEstimate::Variance;
  // Time budget (cost-aware): extra samples ~ (estimate / cost)^power per block,
  // spending the uniform allocation's predicted cost instead of its sample count,
  // with a pixel's cost per sample = its primary march steps (attachment 2's w)
  // + cost_offset x the image's mean steps (the path's other rays). False: the
  // samples budget (every sample costs alike).
  bool time_budget = false;
  float cost_offset = 1.0f;
  // Time budget: a measured per-pixel cost per sample, w x h (iterationsCost);
  // empty: the steps above.
  std::vector<float> cost_per_sample;
};

// Per-pixel cost per sample for a w x h render from an `iterations` view render
// (red = the kernel's loop iterations, any size: nearest pixel), smoothed over
// 3x3 (one sample's path length is as noisy as the sample).
std::vector<float> iterationsCost(const FloatImage& iterations, uint32_t w, uint32_t h);

struct AdaptiveStats {
  uint32_t first_spp = 0;       // per pixel, both halves
  uint32_t max_spp = 0;         // the most any pixel took
  uint32_t rounds = 0;          // extra-phase passes per half
  uint64_t draws = 0;           // scissored draws of the extra phase, both halves
  double first_seconds = 0, estimate_seconds = 0, extra_seconds = 0;
  // Time budget: the extra phase's predicted cost over a uniform one's (1 up to
  // rounding), and its sample count over the uniform one's (below 1: the samples
  // moved to expensive pixels are fewer).
  double predicted_cost_ratio = 1, sample_ratio = 1;
};

// Extra samples per pixel and half, w x h row-major: block-constant except one
// block that takes the remainder, at most `cap_half` each. `weight`: per-pixel
// estimate (>= 0); a block takes its largest pixel's, to the power `power`.
// Without `cost` (empty) the counts sum to exactly extra_half x w x h. With a
// per-pixel cost per sample (> 0; a block takes its pixels' mean), a block's
// count is ~ (weight / cost)^power and the counts' summed cost equals that of
// extra_half everywhere less under one sample's cost; equal costs give the
// allocation without them, bit for bit.
std::vector<uint32_t> allocateExtraSamples(const std::vector<float>& weight, uint32_t w, uint32_t h,
                                           uint32_t block, float power, uint32_t extra_half,
                                           uint32_t cap_half,
                                           const std::vector<float>& cost = {});

// Renders settings.spp samples per pixel on average as two halves (see above);
// returns their merge with RenderOutput::sample_counts, the halves in `*halves`
// (samples_a = samples_b = the mean per half). Fewer than 4 spp or a non-beauty
// view: renderHalves. Settings::jittered_aovs as in renderHalves.
RenderOutput renderAdaptive(Renderer& renderer, const CameraDesc& camera,
                            const RenderSettings& settings, const AdaptiveParams& params,
                            SampleHalves* halves, AdaptiveStats* stats = nullptr,
                            const ProgressCallback& progress = {},
                            const std::atomic<bool>* interrupt = nullptr);

}  // namespace sdfc
