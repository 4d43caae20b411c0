#include "denoise_svgf.h"

#include "denoise_features.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace sdfc {
namespace {

constexpr float kLuminance[3] = {0.2126f, 0.7152f, 0.0722f};  // Rec. 709
constexpr float kAlbedoFloor = Features::kAlbedoFloor;
// B3-spline taps (1, 4, 6, 4, 1) / 16 (Dammertz et al. 2010; SVGF uses the same).
constexpr float kB3[5] = {1.0f / 16, 1.0f / 4, 3.0f / 8, 1.0f / 4, 1.0f / 16};
// Luminance edge stop where the noise estimate is zero: differences this small
// (in demodulated units, about irradiance) still mix.
constexpr float kLuminanceEpsilon = 1e-4f;


float demodulator(const Features& f, size_t i, int c) {
  return f.hit[i] ? std::max(f.albedo[i * 3 + c], kAlbedoFloor) : 1.0f;
}

}  // namespace

FloatImage varianceFromHalves(const FloatImage& half_a, uint32_t samples_a,
                              const FloatImage& half_b, uint32_t samples_b) {
  requireSameSize(half_a, half_b, "svgf: second half size differs from colour");
  FloatImage out(half_a.width, half_a.height);
  const double n = double(samples_a) + double(samples_b);
  const double scale = n > 0 ? double(samples_a) * double(samples_b) / (n * n) : 0.0;
  for (size_t i = 0; i < out.pixelCount(); ++i) {
    double luminance = 0;
    for (int c = 0; c < 3; ++c) {
      const double d = double(half_a.rgba[i * 4 + c]) - double(half_b.rgba[i * 4 + c]);
      out.rgba[i * 4 + c] = float(d * d * scale);
      luminance += kLuminance[c] * d;
    }
    out.rgba[i * 4 + 3] = float(luminance * luminance * scale);
  }
  return out;
}

FloatImage svgfFilter(const FloatImage& color, const FloatImage& variance,
                      const FloatImage& normal_depth, const FloatImage& albedo_steps,
                      const SvgfParams& params) {
  requireSameSize(color, variance, "svgf: variance size differs from colour");
  requireSameSize(color, normal_depth, "svgf: normal/depth size differs from colour");
  requireSameSize(color, albedo_steps, "svgf: albedo size differs from colour");
  const int w = int(color.width), h = int(color.height);
  const size_t n = color.pixelCount();
  const Features f(normal_depth, albedo_steps);

  // Demodulated colour (irradiance-like: material colour is not noise) and the
  // variance of its luminance. The channels of one path share its randomness, so
  // their deviations add (perfect correlation) rather than their variances.
  std::vector<float> current(n * 3), next(n * 3);
  std::vector<float> var(n, 0.0f), var_next(n, 0.0f);
  for (size_t i = 0; i < n; ++i) {
    float sigma = 0;
    for (int c = 0; c < 3; ++c) {
      const float a = demodulator(f, i, c);
      current[i * 3 + c] = color.rgba[i * 4 + c] / a;
      sigma += kLuminance[c] * std::sqrt(std::max(variance.rgba[i * 4 + c], 0.0f)) / a;
    }
    var[i] = sigma * sigma;
  }
  auto luminance = [](const float* c) {
    return kLuminance[0] * c[0] + kLuminance[1] * c[1] + kLuminance[2] * c[2];
  };

  auto stopped = [&] { return params.interrupt && params.interrupt->load(std::memory_order_relaxed); };
  // Two halves give one degree of freedom per pixel: average the variance over
  // a window of the same surface (no luminance term) before it steers anything.
  {
    const int r = std::max(params.variance_radius, 0);
    forEachRow(h, [&](int y) {
      if (stopped()) return;
      for (int x = 0; x < w; ++x) {
        const size_t p = size_t(y) * w + x;
        if (!f.hit[p]) continue;
        double sum = 0, weight_sum = 0;
        for (int dy = -r; dy <= r; ++dy)
          for (int dx = -r; dx <= r; ++dx) {
            const int qx = x + dx, qy = y + dy;
            if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
            const size_t q = size_t(qy) * w + qx;
            if (!f.hit[q]) continue;
            const float weight = q == p ? 1.0f : f.weight(p, q, dx, dy, params.sigma_normal, params.sigma_depth, params.sigma_albedo);
            sum += double(weight) * var[q];
            weight_sum += weight;
          }
        var_next[p] = float(sum / weight_sum);
      }
    });
    if (stopped()) return {};
    for (size_t p = 0; p < n; ++p)
      if (f.hit[p]) var[p] = var_next[p];
  }

  for (int iteration = 0; iteration < params.iterations; ++iteration) {
    const int step = 1 << iteration;
    forEachRow(h, [&](int y) {
      if (stopped()) return;
      for (int x = 0; x < w; ++x) {
        const size_t p = size_t(y) * w + x;
        const float* cp = &current[p * 3];
        if (!f.hit[p]) {  // the sky is not filtered, nor mixed with surfaces
          std::copy(cp, cp + 3, &next[p * 3]);
          var_next[p] = var[p];
          continue;
        }
        // The centre's noise, from a 3x3 Gaussian of the variance (SVGF sec. 4.5).
        double local = 0, local_weight = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int qx = x + dx, qy = y + dy;
            if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
            const size_t q = size_t(qy) * w + qx;
            if (!f.hit[q]) continue;
            const float g = (dx == 0 ? 0.5f : 0.25f) * (dy == 0 ? 0.5f : 0.25f);
            local += g * var[q];
            local_weight += g;
          }
        const float sigma_l =
            params.sigma_luminance * std::sqrt(float(std::max(local / local_weight, 0.0))) +
            kLuminanceEpsilon;
        const float lp = luminance(cp);
        double sum[3] = {0, 0, 0}, weight_sum = 0, var_sum = 0;
        for (int j = -2; j <= 2; ++j)
          for (int i = -2; i <= 2; ++i) {
            const int dx = i * step, dy = j * step;
            const int qx = x + dx, qy = y + dy;
            if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
            const size_t q = size_t(qy) * w + qx;
            if (!f.hit[q]) continue;
            const float* cq = &current[q * 3];
            float weight = kB3[i + 2] * kB3[j + 2];
            if (q != p)
              weight *= f.weight(p, q, dx, dy, params.sigma_normal, params.sigma_depth, params.sigma_albedo) *
                        std::exp(-std::fabs(lp - luminance(cq)) / sigma_l);
            for (int c = 0; c < 3; ++c) sum[c] += double(weight) * cq[c];
            weight_sum += weight;
            var_sum += double(weight) * weight * var[q];
          }
        for (int c = 0; c < 3; ++c) next[p * 3 + c] = float(sum[c] / weight_sum);
        var_next[p] = float(var_sum / (weight_sum * weight_sum));  // centre tap always counts
      }
    });
    if (stopped()) return {};
    std::swap(current, next);
    std::swap(var, var_next);
    if (params.progress) params.progress(double(iteration + 1) / params.iterations);
  }

  FloatImage out = color;
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) out.rgba[i * 4 + c] = current[i * 3 + c] * demodulator(f, i, c);
  return out;
}

FloatImage svgfDenoise(const SampleHalves& halves, const FloatImage& normal_depth,
                       const FloatImage& albedo_steps, const SvgfParams& params) {
  const double n_a = halves.samples_a, n_b = halves.samples_b, n = n_a + n_b;
  FloatImage mean(halves.a.width, halves.a.height, 1.0f);
  for (size_t i = 0; i < mean.pixelCount(); ++i)
    for (int c = 0; c < 3; ++c)
      mean.rgba[i * 4 + c] =
          float((n_a * halves.a.rgba[i * 4 + c] + n_b * halves.b.rgba[i * 4 + c]) / n);
  const FloatImage variance =
      varianceFromHalves(halves.a, halves.samples_a, halves.b, halves.samples_b);
  return svgfFilter(mean, variance, normal_depth, albedo_steps, params);
}

}  // namespace sdfc
