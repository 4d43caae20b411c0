#include "denoise_fireflies.h"

#include <algorithm>
#include <vector>

namespace sdfc {
namespace {

// Rec. 709 luminance of a linear pixel (negatives count as 0).
inline float luminance(const float* rgb) {
  return std::max(0.0f, 0.2126f * rgb[0] + 0.7152f * rgb[1] + 0.0722f * rgb[2]);
}

std::vector<float> luminances(const FloatImage& image) {
  std::vector<float> out(image.pixelCount());
  for (size_t i = 0; i < out.size(); ++i) out[i] = luminance(&image.rgba[i * 4]);
  return out;
}

// Scales `self`'s pixels above their bound: the larger of `ratio` x the median
// of both halves over the 5x5 around them (robust while up to half of them are
// fireflies, as seen through glass) and `ratio` x the other half's own pixel
// (what both halves see is kept: a highlight, a thin bright line).
size_t clampAgainst(FloatImage& self, const std::vector<float>& l_self, const std::vector<float>& l_other,
                    float ratio) {
  const int w = int(self.width), h = int(self.height);
  size_t changed = 0;
  std::vector<float> around;
  around.reserve(50);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t p = size_t(y) * w + x;
      if (!(l_self[p] > ratio * l_other[p])) continue;  // within the other half's own bound
      around.clear();
      for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) {
          const int qx = x + dx, qy = y + dy;
          if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
          const size_t q = size_t(qy) * w + qx;
          around.push_back(l_self[q]);
          around.push_back(l_other[q]);
        }
      auto middle = around.begin() + around.size() / 2;
      std::nth_element(around.begin(), middle, around.end());
      const float bound = ratio * std::max(*middle, l_other[p]);
      if (l_self[p] > bound) {
        const float scale = bound / l_self[p];
        for (int c = 0; c < 3; ++c) self.rgba[p * 4 + c] *= scale;
        ++changed;
      }
    }
  return changed;
}

}  // namespace

size_t clampFireflies(SampleHalves& halves, const FireflyParams& params) {
  // Both bounds from the unclamped halves: the result does not depend on the order.
  const std::vector<float> la = luminances(halves.a), lb = luminances(halves.b);
  return clampAgainst(halves.a, la, lb, params.ratio) + clampAgainst(halves.b, lb, la, params.ratio);
}

}  // namespace sdfc
