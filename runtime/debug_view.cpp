#include "debug_view.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "image_io.h"
#include "renderer.h"
#include "shader_interface.h"

namespace sdfc {

namespace {

// Misses in the depth view: a neutral grey, outside the colour map.
constexpr float kMissGrey = 0.05f;  // linear, sRGB byte 63

void putMapped(float t, float* pixel) {
  float rgb[3];
  viridis(t, rgb);
  for (int c = 0; c < 3; ++c) pixel[c] = srgbDecode(rgb[c]);
  pixel[3] = 1.0f;
}

}  // namespace

void viridis(float t, float rgb[3]) {
  // Matt Zucker's degree-6 least-squares polynomial fit of matplotlib's viridis
  // (van der Walt and Smith, 2015), "viridis approximation", Shadertoy, 2019;
  // within about 1/255 of the table. Coefficients of t^0 .. t^6 per channel.
  static constexpr double kC[7][3] = {
      {0.2777273272234177, 0.005407344544966578, 0.3340998053353061},
      {0.1050930431085774, 1.404613529898575, 1.384590162594685},
      {-0.3308618287255563, 0.214847559468213, 0.09509516302823659},
      {-4.634230498983486, -5.799100973351585, -19.33244095627987},
      {6.228269936347081, 14.17993336680509, 56.69055260068105},
      {4.776384997670288, -13.74514537774601, -65.35303263337234},
      {-5.435455855934631, 4.645852612178535, 26.3124352495832},
  };
  const double x = std::isnan(t) ? 0.0 : std::clamp<double>(t, 0.0, 1.0);
  for (int c = 0; c < 3; ++c) {
    double v = kC[6][c];
    for (int k = 5; k >= 0; --k) v = v * x + kC[k][c];  // Horner
    rgb[c] = std::clamp(static_cast<float>(v), 0.0f, 1.0f);
  }
}

DebugViewBudget debugViewBudget(uint32_t max_steps, const RenderSettings& settings) {
  DebugViewBudget b;
  b.max_steps = std::max<uint32_t>(1, max_steps);
  b.iterations = std::max<uint32_t>(1, settings.loop_iterations_per_sample + settings.loop_iterations_per_pass);
  return b;
}

bool debugViewNeedsMapping(uint32_t view) {
  return view == gpu::kViewDepth || view == gpu::kViewSteps || view == gpu::kViewIterations;
}

FloatImage debugViewForDisplay(uint32_t view, const FloatImage& raw, const DebugViewBudget& budget) {
  if (!debugViewNeedsMapping(view)) return raw;
  FloatImage out(raw.width, raw.height);
  const size_t n = raw.pixelCount();
  if (view == gpu::kViewDepth) {
    // The scene's hit range in this image, log, from the 1st to the 90th
    // percentile of the hits: a ground plane reaches hundreds of units where the
    // subject is at tens (castle: 15 to 1680, median 22), and a min-max range
    // drew the whole subject in one colour. The farthest tenth is drawn darkest.
    std::vector<float> hits;
    for (size_t i = 0; i < n; ++i) {
      const float d = raw.rgba[i * 4];
      if (d >= 0 && std::isfinite(d)) hits.push_back(d);
    }
    float lo = 1.0f, hi = 1.0f;
    if (!hits.empty()) {
      auto at = [&](double q) {
        auto it = hits.begin() + std::ptrdiff_t(q * double(hits.size() - 1));
        std::nth_element(hits.begin(), it, hits.end());
        return *it;
      };
      lo = std::max(at(0.01), 1e-6f);
      hi = at(0.90);
    }
    const float span = hi > lo ? std::log(hi / lo) : 1.0f;
    for (size_t i = 0; i < n; ++i) {
      const float d = raw.rgba[i * 4];
      if (!(d >= 0) || !std::isfinite(d)) {
        std::fill_n(&out.rgba[i * 4], 3, kMissGrey);
        out.rgba[i * 4 + 3] = 1.0f;
        continue;
      }
      putMapped(1.0f - std::log(std::max(d, lo) / lo) / span, &out.rgba[i * 4]);
    }
    return out;
  }
  const double top = std::log1p(double(view == gpu::kViewSteps ? budget.max_steps : budget.iterations));
  for (size_t i = 0; i < n; ++i) {
    const double count = std::max(0.0f, raw.rgba[i * 4]);
    putMapped(static_cast<float>(top > 0 ? std::log1p(count) / top : 0.0), &out.rgba[i * 4]);
  }
  return out;
}

}  // namespace sdfc
