// CPU denoisers for the rendered float images.
//  - Bilateral: Tomasi & Manduchi 1998, Gaussian spatial and range weights,
//    the range term on the RGB colour difference (5x5, sigma_s 10, sigma_r 0.06).
//  - ATrous: edge-avoiding A-Trous wavelet filter, Dammertz et al. 2010,
//    "Edge-Avoiding A-Trous Wavelet Transform for fast Global Illumination
//    Filtering": 5x5 B3-spline taps spread 2^i apart, edge-stopping weights on
//    colour, normal, depth and albedo; the colour is divided by the albedo first
//    (demodulation) and multiplied back afterwards.
//  - Svgf: variance-guided A-Trous with per-pixel strength selection
//    (denoise_svgf.h); needs two half-sample renders (renderHalves in renderer.h).
//  - Nlm: dual-buffer joint NL-means, two passes (denoise_nlm.h); also needs
//    the two halves.
//  - Nlr: nlm's weights with a first-order regression on features averaged over
//    the jittered samples (nlrParams in denoise_nlm.h). The best of these at equal
//    samples (docs/denoise.md).
//  - NlrFast: nlr in one pass over a smaller window (nlrFastParams), about 40%
//    of its time: an animation's default, where the filter runs every frame.
#pragma once
#include <atomic>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "denoise_nlm.h"
#include "denoise_svgf.h"
#include "float_image.h"

namespace sdfc {

enum class Denoiser { None, Bilateral, ATrous, Svgf, Nlm, Nlr, NlrFast };

// "none", "bilateral", "atrous" (also "a-trous"), "svgf", "nlm", "nlr", "nlr-fast";
// nullopt otherwise.
std::optional<Denoiser> parseDenoiser(std::string_view name);
const char* denoiserName(Denoiser denoiser);

struct BilateralParams {
  int radius = 2;  // 5x5 window
  float sigma_spatial = 10.0f;  // pixels
  float sigma_range = 0.06f;    // linear radiance units, on |rgb_p - rgb_q|
};

FloatImage bilateralFilter(const FloatImage& color, const BilateralParams& params = {});

struct ATrousParams {
  int iterations = 5;         // tap spacing 1, 2, 4, 8, 16 -> 61x61 footprint
  float sigma_color = 0.5f;   // on demodulated colour; halved every iteration (Dammertz 2010)
  float sigma_normal = 0.3f;  // on |n_p - n_q|
  // On the depth difference relative to the centre depth, per pixel of tap
  // distance: planes seen at an angle keep their weight at wide spacings.
  float sigma_depth = 0.05f;
  float sigma_albedo = 0.1f;  // on |albedo_p - albedo_q|
  bool demodulate_albedo = true;
};

// `normal_depth`, `albedo_steps`: the renderer's attachments 1 and 2 (depth w < 0
// means the primary ray missed; hits and misses never mix).
FloatImage atrousFilter(const FloatImage& color, const FloatImage& normal_depth,
                        const FloatImage& albedo_steps, const ATrousParams& params = {});

// Whether `denoiser` needs two half-sample renders (SampleHalves).
bool needsVariance(Denoiser denoiser);
// Whether its features are best averaged over the jittered samples
// (RenderSettings::jittered_aovs) rather than taken from one unjittered ray.
bool wantsJitteredAovs(Denoiser denoiser);
// Whether its jittered features should also pass through specular first hits
// (RenderSettings::specular_aovs; docs/denoise.md: nlr, glass Menger -7 to -27%).
bool wantsSpecularAovs(Denoiser denoiser);

// What a caller may do to a running denoise: stop it (nlm, nlr: between blocks
// of pixels, svgf between rows; then denoise returns an empty image) and hear
// how far it is (nlm, nlr, svgf).
struct DenoiseControl {
  const std::atomic<bool>* interrupt = nullptr;
  std::function<void(double)> progress;  // NlmParams::progress
};

// The wall seconds `denoiser` is expected to take on `pixels` on this machine's
// cores (hardware_concurrency, at most 8), from the CPU cost measured in
// docs/denoise.md; `select_strengths` candidates (--denoise-select) for nlm/nlr.
// For the progress bar's ETA before the filter reports its own progress.
double predictedDenoiseSeconds(Denoiser denoiser, size_t pixels, size_t select_strengths = 0);

// Dispatch with default parameters; None returns `color` unchanged. Svgf, Nlm and Nlr
// need `halves` (with samples in both) and throw std::invalid_argument without them.
// `select_strengths` (nlm, nlr; `--denoise-select`): the last pass's colour
// strengths chosen among per pixel (NlmParams::select_k); empty: off.
FloatImage denoise(Denoiser denoiser, const FloatImage& color, const FloatImage& normal_depth,
                   const FloatImage& albedo_steps, const SampleHalves* halves = nullptr,
                   const std::vector<float>& select_strengths = {},
                   const DenoiseControl& control = {});

}  // namespace sdfc
