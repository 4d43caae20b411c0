// Variance-guided, feature-guided A-Trous denoiser: the spatial part of SVGF
// (Schied et al. 2017, "Spatiotemporal Variance-Guided Filtering", sec. 4.4-4.5),
// with the per-pixel variance taken from two independent half-sample renders
// instead of a temporal history (as NFOR's dual buffers, Bitterli et al. 2016).
//
// Each of `iterations` A-Trous passes (5x5 B3-spline taps, spacing 2^i) weights a
// neighbour by its first-hit normal (max(0, n.n)^sigma_normal), depth (against the
// local depth gradient), albedo, and demodulated-luminance difference measured in
// standard deviations of the centre pixel's noise (sigma_luminance). The noise
// estimate shrinks with the sample count, so the filter's strength does too: at
// convergence only pixels of equal value are mixed, and the filter has no bias.
#pragma once
#include <atomic>
#include <cstdint>
#include <functional>

#include "float_image.h"

namespace sdfc {

struct SvgfParams {
  int iterations = 5;             // spacing 1..16 -> 61x61 footprint
  float sigma_luminance = 4.0f;   // luminance edge stop, in noise standard deviations
  float sigma_normal = 128.0f;    // exponent on max(0, n_p . n_q)
  float sigma_depth = 1.0f;       // on |z_p - z_q| / |grad z . offset|
  float sigma_albedo = 0.05f;     // on (a_p - a_q) / (a_p + a_q) per channel
  int variance_radius = 3;        // feature-weighted prefilter of the two-half variance
  // Set (Ctrl-C): the filter stops between rows, and svgfFilter returns an empty image.
  const std::atomic<bool>* interrupt = nullptr;
  std::function<void(double)> progress;  // the share done, after each iteration
};

// Per-channel variance of the sample-weighted mean of two independent renders
// (samples_a and samples_b samples), in rgb; a = the same for luminance.
// Var(mean) = (a - b)^2 * n_a * n_b / (n_a + n_b)^2.
FloatImage varianceFromHalves(const FloatImage& half_a, uint32_t samples_a,
                              const FloatImage& half_b, uint32_t samples_b);

// `color`: the mean of all samples; `variance`: varianceFromHalves of its two
// halves; `normal_depth`, `albedo_steps`: the renderer's attachments 1 and 2.
FloatImage svgfFilter(const FloatImage& color, const FloatImage& variance,
                      const FloatImage& normal_depth, const FloatImage& albedo_steps,
                      const SvgfParams& params = {});  // empty when params.interrupt was set

// Two independent renders of one pixel set: the input `--denoise svgf` needs.
struct SampleHalves {
  FloatImage a, b;  // means of samples [0, samples_a) and [samples_a, samples_a + samples_b)
  uint32_t samples_a = 0, samples_b = 0;
};
// svgfFilter of the halves' sample-weighted mean, with varianceFromHalves.
FloatImage svgfDenoise(const SampleHalves& halves, const FloatImage& normal_depth,
                       const FloatImage& albedo_steps, const SvgfParams& params = {});

}  // namespace sdfc
