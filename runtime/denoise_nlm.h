// Dual-buffer joint non-local-means denoiser (`--denoise nlm`).
//
// The samples arrive as two independent halves (SampleHalves). Each half is
// filtered with weights computed on the *other* half (cross-filtering, as in
// Rousselle et al. 2012, "Adaptive rendering with non-local means filtering",
// and NFOR, Bitterli et al. 2016), so a pixel's weights are independent of the
// noise they average. A weight is the smaller of
//  - the colour weight of NL-means with variance-normalised patch distances
//    (Rousselle et al. 2012, eq. 5: squared difference minus the expected noise,
//    over the summed variances), and
//  - the first-hit feature weight (normal, depth, albedo; denoise_features.h),
// the joint filter of Rousselle et al. 2013. A second pass filters the original
// halves again with weights computed on the first pass's output, whose lower
// noise gives better weights. The two filtered halves are averaged.
//
// No bias at convergence: the colour distance is measured in units of the
// estimated variance, so as the variance falls to zero a neighbour is only
// accepted if its value is equal to the pixel's; with zero variance the filter
// is the identity.
#pragma once
#include "denoise_svgf.h"  // SampleHalves
#include <atomic>
#include <functional>
#include <vector>

#include "denoise_fireflies.h"
#include "denoise_select.h"
#include "float_image.h"

namespace sdfc {

struct NlmParams {
  int radius = 5;           // search window (2r+1)^2
  int patch_radius = 1;     // patches (2f+1)^2
  float k_first = 0.45f;    // colour strength, pass 1 (guides: the noisy halves)
  float k_second = 1.0f;    // colour strength of later passes (guides: the previous pass's output)
  int passes = 2;
  int variance_radius = 1;  // box over (guide_a - guide_b)^2, (2r+1)^2
  float sigma_normal = 128.0f, sigma_depth = 1.0f, sigma_albedo = 0.05f;  // feature weight
  bool feature_weights = true;  // weight = min(colour, feature); off: the colour weight alone
  // The last pass fits the colour to the features by weighted least squares
  // (first order) and takes the fit at the pixel instead of the weighted mean.
  bool regression = false;
  float ridge = 1e-3f;  // on the slopes, times the sum of the weights
  // Non-empty: the last pass runs once per strength in select_k (instead of
  // k_second) and each pixel takes the candidate of least estimated error
  // (denoise_select.h). (Each strength's weighted mean as a further candidate
  // was measured worse on the castle and colonnade: docs/denoise.md.)
  std::vector<float> select_k;
  SelectParams select;
  // Fireflies clamped in both halves first (denoise_fireflies.h): without it a
  // caustic's fireflies become window-sized squares.
  bool clamp_fireflies = true;
  FireflyParams fireflies;
  // Set (Ctrl-C): the filter stops between blocks of pixels, within
  // milliseconds, and nlmDenoise returns an empty image.
  const std::atomic<bool>* interrupt = nullptr;
  // Called now and then with the share of the filter done (0..1], from the
  // filter's threads, one call at a time.
  std::function<void(double)> progress;
};

// `--denoise nlr`: NL-means-weighted first-order regression on features averaged
// over the jittered samples (RenderSettings::jittered_aovs). Measured on castle,
// colonnade and glass Menger at 640x360 16 spp (docs/denoise.md): the colour
// weight alone (the blended edge features would reject true neighbours), a
// second-pass strength of 1.25.
inline NlmParams nlrParams() {
  NlmParams params;
  params.regression = true;
  params.feature_weights = false;
  params.k_second = 1.25f;
  return params;
}

// `--denoise nlr-fast`, an animation's default (api/render_defaults.h): nlr's fit
// in one pass over a 7 x 7 window instead of two over 11 x 11, about 40% of
// nlr's time. One pass takes its weights from the noisy halves, so its colour
// strength sits between nlr's two (0.45, 1.25). Measured on morph at 320x180,
// 8 spp (bench/results/anim_denoise.md): relMSE 8.0e-5 against nlr's 7.7e-5,
// and 4 more samples per pixel cost less than the time it saves and bring the
// error below nlr's at 8 (6.0e-5).
inline NlmParams nlrFastParams() {
  NlmParams params = nlrParams();
  params.radius = 3;
  params.passes = 1;
  params.k_first = 0.7f;
  return params;
}

// The denoised sample-weighted mean of the halves. `normal_depth`, `albedo_steps`:
// the renderer's attachments 1 and 2. Throws std::invalid_argument on size mismatch.
// `filtered` (if not null) gets each half filtered on its own (adaptive sampling's
// cross-half error estimate, adaptive.h). Empty (and `filtered` untouched) when
// params.interrupt was set before the end.
FloatImage nlmDenoise(const SampleHalves& halves, const FloatImage& normal_depth,
                      const FloatImage& albedo_steps, const NlmParams& params = {},
                      SampleHalves* filtered = nullptr);

}  // namespace sdfc
