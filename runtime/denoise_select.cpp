#include "denoise_select.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "denoise_features.h"

namespace sdfc {
namespace {

using Plane = std::vector<float>;

// Blends one half's candidates by their smoothed squared difference from the
// other half, e_k: weight (min_j e_j / e_k)^sharpness. Returns the index of the
// least e_k per pixel.
std::vector<int> blendAgainst(const std::vector<Plane>& candidates, const Plane& other,
                              const Plane& scale, int w, int h, const SelectParams& params,
                              Plane& out) {
  const size_t n = size_t(w) * h;
  std::vector<Plane> errors;
  std::vector<int> best(n, 0);
  Plane error(n);
  for (size_t k = 0; k < candidates.size(); ++k) {
    const Plane& f = candidates[k];
    for (size_t i = 0; i < n; ++i) {
      float sum = 0;
      for (int c = 0; c < 3; ++c) {
        const float d = f[i * 3 + c] - other[i * 3 + c];
        sum += d * d;
      }
      error[i] = sum * scale[i];
    }
    errors.push_back(boxMean(error, w, h, 1, params.radius));
    for (size_t i = 0; i < n; ++i)
      if (errors.back()[i] < errors[size_t(best[i])][i]) best[i] = int(k);
  }
  out.assign(n * 3, 0.0f);
  forEachRow(h, [&](int y) {
    for (size_t i = size_t(y) * w; i < size_t(y + 1) * w; ++i) {
      const float least = errors[size_t(best[i])][i];
      float weight_sum = 0, sum[3] = {0, 0, 0};
      for (size_t k = 0; k < candidates.size(); ++k) {
        // The least is weighted 1, so the sum is never 0; equal errors share.
        const float weight =
            errors[k][i] > least ? std::pow(least / errors[k][i], params.sharpness) : 1.0f;
        weight_sum += weight;
        for (int c = 0; c < 3; ++c) sum[c] += weight * candidates[k][i * 3 + c];
      }
      for (int c = 0; c < 3; ++c) out[i * 3 + c] = sum[c] / weight_sum;
    }
  });
  return best;
}

}  // namespace

void selectPerPixel(const std::vector<Plane>& candidates_a, const std::vector<Plane>& candidates_b,
                    const Plane& a, const Plane& b, int w, int h, const SelectParams& params,
                    Plane& out_a, Plane& out_b, std::vector<int>* choice) {
  const size_t n = size_t(w) * h;
  if (candidates_a.empty() || candidates_a.size() != candidates_b.size())
    throw std::invalid_argument("selectPerPixel: needs as many candidates for each half");
  // 1 / (value^2 + floor) from the candidates' mean luminance-free average.
  Plane scale(n, 1.0f);
  if (params.relative_floor > 0)
    for (size_t i = 0; i < n; ++i) {
      float sum = 0;
      for (int c = 0; c < 3; ++c) {
        float v = 0;
        for (size_t k = 0; k < candidates_a.size(); ++k)
          v += candidates_a[k][i * 3 + c] + candidates_b[k][i * 3 + c];
        v /= float(2 * candidates_a.size());
        sum += v * v;
      }
      scale[i] = 1.0f / (sum / 3.0f + params.relative_floor);
    }
  const std::vector<int> pick_a = blendAgainst(candidates_a, b, scale, w, h, params, out_a);
  blendAgainst(candidates_b, a, scale, w, h, params, out_b);
  if (choice) *choice = pick_a;
}

}  // namespace sdfc
