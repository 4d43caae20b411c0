// What the feature-guided denoisers (denoise_svgf, denoise_nlm) share: the
// renderer's first-hit attachments unpacked into flat per-pixel arrays, the
// edge-stopping weight between two pixels (and, from for_each_row.h, a
// row-parallel loop).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "float_image.h"
#include "for_each_row.h"

namespace sdfc {

// Mean of `in` (w x h pixels of `channels` values) over each pixel's
// (2 radius + 1)^2 box, counting only the pixels inside the image; separable.
std::vector<float> boxMean(const std::vector<float>& in, int w, int h, int channels, int radius);

// Depth slope at pixel i from the neighbour on the same surface: of the two
// one-sided differences (to i + back, from i + ahead), the smaller (a
// silhouette makes the other one large); 0 with neither neighbour a hit.
// depth(q), hit(q): pixel q's depth and whether it is a surface.
template <typename DepthAt, typename HitAt>
float depthSlope(size_t i, long back, long ahead, bool has_back, bool has_ahead, const DepthAt& depth,
                 const HitAt& hit) {
  float best = 0;
  bool found = false;
  for (int k = 0; k < 2; ++k) {
    const bool ok = k == 0 ? has_back : has_ahead;
    if (!ok) continue;
    const size_t q = size_t(long(i) + (k == 0 ? back : ahead));
    if (!hit(q)) continue;
    const float d = k == 0 ? depth(i) - depth(q) : depth(q) - depth(i);
    if (!found || std::fabs(d) < std::fabs(best)) best = d;
    found = true;
  }
  return best;
}

// Everything the edge-stopping weights read, per pixel, in flat arrays.
struct Features {
  int width = 0, height = 0;
  std::vector<uint8_t> hit;   // the primary ray hit a surface (attachment 1's w >= 0)
  std::vector<float> normal;  // 3 per pixel
  std::vector<float> depth;
  std::vector<float> depth_dx, depth_dy;  // one-sided difference of smaller magnitude
  std::vector<float> albedo;  // 3 per pixel

  // `normal_depth`, `albedo_steps`: the renderer's attachments 1 and 2.
  Features(const FloatImage& normal_depth, const FloatImage& albedo_steps);

  // Product of the normal (max(0, n_p . n_q)^sigma_normal), depth (|z_p - z_q|
  // against the local depth slope) and relative albedo weights of q seen from p
  // (both hits), q at pixel offset (dx, dy).
  float weight(size_t p, size_t q, int dx, int dy, float sigma_normal, float sigma_depth,
               float sigma_albedo) const {
    const float* np = &normal[p * 3];
    const float* nq = &normal[q * 3];
    const float cosine = std::max(0.0f, np[0] * nq[0] + np[1] * nq[1] + np[2] * nq[2]);
    const float w_normal = power(cosine, sigma_normal);
    if (w_normal < kNegligible) return 0.0f;
    const float expected = std::fabs(depth_dx[p] * float(dx) + depth_dy[p] * float(dy));
    // A small tolerance relative to the depth (float32 hit jitter, curvature).
    const float tolerance = 2e-4f * depth[p] * std::sqrt(float(dx * dx + dy * dy));
    const float w_depth =
        expNegative(std::fabs(depth[p] - depth[q]) / (sigma_depth * expected + tolerance + 1e-12f));
    if (w_depth < kNegligible) return 0.0f;
    // Relative albedo difference: demodulated colour is divided by the albedo, so
    // a dark albedo's value must never be remodulated by a brighter one (a 0.001
    // pixel mixed into a 0.04 one came back 40x too bright on the colonnade).
    const float* ap = &albedo[p * 3];
    const float* aq = &albedo[q * 3];
    if (ap[0] == aq[0] && ap[1] == aq[1] && ap[2] == aq[2]) return w_normal * w_depth;  // one material
    float da = 0;
    for (int c = 0; c < 3; ++c) {
      const float d = (ap[c] - aq[c]) / (ap[c] + aq[c] + 2 * kAlbedoFloor);
      da += d * d;
    }
    const float w_albedo = expNegative(da / (sigma_albedo * sigma_albedo));
    return w_normal * w_depth * w_albedo;
  }

  // Weights below this are 0 (they would change a pixel by less than float precision).
  static constexpr float kNegligible = 1e-7f;
  // exp(-x) for x >= 0, without the slow underflow path of expf far below kNegligible.
  static float expNegative(float x) { return x > 17.0f ? 0.0f : std::exp(-x); }
  // x^e for x in [0, 1]; by squaring when e is a small whole number (128: 7 products).
  static float power(float x, float e) {
    if (e == std::floor(e) && e >= 0.0f && e <= 1024.0f) {
      float result = 1.0f;
      for (int n = int(e); n > 0; n >>= 1, x *= x)
        if (n & 1) result *= x;
      return result;
    }
    return std::pow(x, e);
  }

  static constexpr float kAlbedoFloor = 1e-3f;  // black albedo does not divide by zero
};

}  // namespace sdfc
