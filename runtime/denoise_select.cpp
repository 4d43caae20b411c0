#include "denoise_select.h"

#include <algorithm>
#include <stdexcept>

#include "denoise_features.h"

namespace sdfc {
namespace {

using Plane = std::vector<float>;

// Mean over the (2r+1)^2 box of the pixels inside the image, separable.
Plane boxMean(const Plane& in, int w, int h, int r) {
  Plane row(in.size()), out(in.size());
  forEachRow(h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      float sum = 0;
      const int x0 = std::max(0, x - r), x1 = std::min(w - 1, x + r);
      for (int q = x0; q <= x1; ++q) sum += in[size_t(y) * w + q];
      row[size_t(y) * w + x] = sum / float(x1 - x0 + 1);
    }
  });
  forEachRow(h, [&](int y) {
    const int y0 = std::max(0, y - r), y1 = std::min(h - 1, y + r);
    for (int x = 0; x < w; ++x) {
      float sum = 0;
      for (int q = y0; q <= y1; ++q) sum += row[size_t(q) * w + x];
      out[size_t(y) * w + x] = sum / float(y1 - y0 + 1);
    }
  });
  return out;
}

// Smoothed per-pixel squared difference of each candidate of one half against
// the other half, then the argmin per pixel.
std::vector<int> chooseAgainst(const std::vector<Plane>& candidates, const Plane& other,
                               const Plane& scale, int w, int h, int radius) {
  const size_t n = size_t(w) * h;
  std::vector<int> best(n, 0);
  Plane best_error(n, 0.0f), error(n);
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
    const Plane smooth = boxMean(error, w, h, radius);
    for (size_t i = 0; i < n; ++i)
      if (k == 0 || smooth[i] < best_error[i]) {
        best_error[i] = smooth[i];
        best[i] = int(k);
      }
  }
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
  const std::vector<int> pick_a = chooseAgainst(candidates_a, b, scale, w, h, params.radius);
  const std::vector<int> pick_b = chooseAgainst(candidates_b, a, scale, w, h, params.radius);
  out_a.resize(n * 3);
  out_b.resize(n * 3);
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      out_a[i * 3 + c] = candidates_a[size_t(pick_a[i])][i * 3 + c];
      out_b[i * 3 + c] = candidates_b[size_t(pick_b[i])][i * 3 + c];
    }
  if (choice) *choice = pick_a;
}

}  // namespace sdfc
