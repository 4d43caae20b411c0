// nlr/nlm as they were at ab4eac1 (runtime/denoise_nlm.cpp before issue 48),
// kept here only as the baseline bench/denoise_speed.py times and compares the
// runtime's filter against, on the same input in the same process.
#include "legacy_nlm.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "denoise_features.h"
#include "denoise_select.h"

namespace sdfc {
namespace legacy {
namespace {

constexpr float kEpsilon = 1e-10f;  // Rousselle et al. 2012's epsilon: zero variance, zero reach
constexpr int kTileRows = 16;

// rgb of every pixel, flat.
using Plane = std::vector<float>;

Plane rgbOf(const FloatImage& image) {
  Plane out(image.pixelCount() * 3);
  for (size_t i = 0; i < image.pixelCount(); ++i)
    for (int c = 0; c < 3; ++c) out[i * 3 + c] = image.rgba[i * 4 + c];
  return out;
}

// Per-channel variance of each guide from their difference, smoothed over a box:
// E[(g_a - g_b)^2] = Var a + Var b, and Var a : Var b = n_b : n_a (the halves'
// sample counts n_a, n_b).
void guideVariances(const Plane& ga, const Plane& gb, int w, int h, int radius, double n_a,
                    double n_b, Plane& var_a, Plane& var_b) {
  const size_t n = size_t(w) * h;
  Plane d2(n * 3);
  for (size_t i = 0; i < n * 3; ++i) d2[i] = (ga[i] - gb[i]) * (ga[i] - gb[i]);
  const Plane mean = boxMean(d2, w, h, 3, radius);
  const float share_a = float(n_b / (n_a + n_b)), share_b = float(n_a / (n_a + n_b));
  var_a.resize(n * 3);
  var_b.resize(n * 3);
  for (size_t i = 0; i < n * 3; ++i) {
    var_a[i] = share_a * mean[i];
    var_b[i] = share_b * mean[i];
  }
}

// Per-pixel, per-offset colour distance before the patch average (Rousselle et
// al. 2012, eq. 5, alpha = 1), mean over the channels.
inline float pixelDistance(const float* gp, const float* gq, const float* vp, const float* vq,
                           float k2) {
  float sum = 0;
  for (int c = 0; c < 3; ++c) {
    const float d = gp[c] - gq[c];
    sum += (d * d - (vp[c] + std::min(vp[c], vq[c]))) / (kEpsilon + k2 * (vp[c] + vq[c]));
  }
  return sum * (1.0f / 3.0f);
}

// First-order regression (NFOR, Bitterli et al. 2016, sec. 4; Moon et al. 2014):
// within the window the colour is modelled as c_p + beta . (x_q - x_p), x the
// features (albedo, normal, relative depth), fitted by weighted least squares
// with the NL-means weights; the estimate is the intercept. An edge pixel
// whose features are a blend of two surfaces (jittered AOVs) then takes the
// blend the model predicts from neighbours on either side instead of needing
// look-alikes. With only the centre weighted (zero variance) it is the identity.
constexpr int kRegressors = 8;  // 1, albedo - albedo_p (3), normal - normal_p (3), depth
// Per pixel: sum w z z^T (upper triangle, 36) and sum w z c (8 x 3), z the regressors.
constexpr int kMoments = kRegressors * (kRegressors + 1) / 2 + kRegressors * 3;

inline void regressors(const Features& f, size_t p, size_t q, float* z) {
  z[0] = 1.0f;
  for (int c = 0; c < 3; ++c) {
    z[1 + c] = f.albedo[q * 3 + c] - f.albedo[p * 3 + c];
    z[4 + c] = f.normal[q * 3 + c] - f.normal[p * 3 + c];
  }
  z[7] = (f.depth[q] - f.depth[p]) / std::max(f.depth[p], 1e-6f);
}

inline void addMoments(float* m, const float* z, const float* colour, float weight) {
  if (weight <= 0.0f) return;
  int k = 0;
  for (int i = 0; i < kRegressors; ++i) {
    const float wz = weight * z[i];
    for (int j = i; j < kRegressors; ++j) m[k++] += wz * z[j];
    for (int c = 0; c < 3; ++c) m[k++] += wz * colour[c];
  }
}

// The intercept of the weighted fit: solve (Z^T W Z + ridge W diag(0, 1..1)) beta
// = Z^T W c by Cholesky in double. `out` keeps the weighted mean when the system
// is not positive definite.
void solveIntercept(const float* m, float ridge, float* out) {
  constexpr int n = kRegressors;
  double a[n][n], b[n][3];
  int k = 0;
  for (int i = 0; i < n; ++i) {
    for (int j = i; j < n; ++j) a[i][j] = a[j][i] = m[k++];
    for (int c = 0; c < 3; ++c) b[i][c] = m[k++];
  }
  if (!(a[0][0] > 0)) return;
  for (int i = 1; i < n; ++i) a[i][i] += ridge * a[0][0];
  for (int j = 0; j < n; ++j) {  // a = L L^T, L in the lower triangle
    double d = a[j][j];
    for (int p = 0; p < j; ++p) d -= a[j][p] * a[j][p];
    if (!(d > 1e-12 * a[0][0])) return;
    a[j][j] = std::sqrt(d);
    for (int i = j + 1; i < n; ++i) {
      double v = a[i][j];
      for (int p = 0; p < j; ++p) v -= a[i][p] * a[j][p];
      a[i][j] = v / a[j][j];
    }
  }
  for (int c = 0; c < 3; ++c) {
    double y[n], x[n];
    for (int i = 0; i < n; ++i) {
      double v = b[i][c];
      for (int p = 0; p < i; ++p) v -= a[i][p] * y[p];
      y[i] = v / a[i][i];
    }
    for (int i = n - 1; i >= 0; --i) {
      double v = y[i];
      for (int p = i + 1; p < n; ++p) v -= a[p][i] * x[p];
      x[i] = v / a[i][i];
    }
    out[c] = float(x[0]);
  }
}

// One pass: out_a = ua filtered with weights from guide gb, out_b = ub with
// weights from guide ga.
void crossFilter(const Plane& ua, const Plane& ub, const Plane& ga, const Plane& gb,
                 const Plane& var_a, const Plane& var_b, const Features& f, float k,
                 const NlmParams& params, bool regress, Plane& out_a, Plane& out_b) {
  const int w = f.width, h = f.height, r = params.radius, pr = std::max(params.patch_radius, 0);
  const float k2 = k * k;
  const float patch_norm = 1.0f / float((2 * pr + 1) * (2 * pr + 1));
  out_a.assign(ua.size(), 0.0f);
  out_b.assign(ub.size(), 0.0f);
  const int tiles = (h + kTileRows - 1) / kTileRows;
  std::atomic<int> next_tile{0};
  auto worker = [&] {
    const int rows = kTileRows + 2 * pr;
    // Distances of the rows a tile's patches read, for guide b (filters a) and a.
    std::vector<float> dist_b(size_t(rows) * w), dist_a(size_t(rows) * w);
    std::vector<float> hsum_b(size_t(rows) * w), hsum_a(size_t(rows) * w);
    std::vector<float> sum_a(size_t(kTileRows) * w * 3), sum_b(size_t(kTileRows) * w * 3);
    std::vector<float> wsum_a(size_t(kTileRows) * w), wsum_b(size_t(kTileRows) * w);
    // With `regress`: each pixel's weighted moments of the first-order model.
    std::vector<float> moments_a(regress ? size_t(kTileRows) * w * kMoments : 0);
    std::vector<float> moments_b(moments_a.size());
    for (int tile = next_tile++; tile < tiles; tile = next_tile++) {
      const int y0 = tile * kTileRows, y1 = std::min(h, y0 + kTileRows);
      std::fill(sum_a.begin(), sum_a.end(), 0.0f);
      std::fill(sum_b.begin(), sum_b.end(), 0.0f);
      std::fill(wsum_a.begin(), wsum_a.end(), 0.0f);
      std::fill(wsum_b.begin(), wsum_b.end(), 0.0f);
      std::fill(moments_a.begin(), moments_a.end(), 0.0f);
      std::fill(moments_b.begin(), moments_b.end(), 0.0f);
      for (int oy = -r; oy <= r; ++oy)
        for (int ox = -r; ox <= r; ++ox) {
          // Pixel distances on rows y0 - pr .. y1 + pr (0 where p or q is outside).
          for (int yy = y0 - pr; yy < y1 + pr; ++yy) {
            float* db = &dist_b[size_t(yy - y0 + pr) * w];
            float* da = &dist_a[size_t(yy - y0 + pr) * w];
            const int qy = yy + oy;
            if (yy < 0 || yy >= h || qy < 0 || qy >= h) {
              std::fill(db, db + w, 0.0f);
              std::fill(da, da + w, 0.0f);
              continue;
            }
            for (int x = 0; x < w; ++x) {
              const int qx = x + ox;
              if (qx < 0 || qx >= w) {
                db[x] = da[x] = 0.0f;
                continue;
              }
              const size_t p = (size_t(yy) * w + x) * 3, q = (size_t(qy) * w + qx) * 3;
              db[x] = pixelDistance(&gb[p], &gb[q], &var_b[p], &var_b[q], k2);
              da[x] = pixelDistance(&ga[p], &ga[q], &var_a[p], &var_a[q], k2);
            }
          }
          // Horizontal patch sums.
          for (int row = 0; row < (y1 - y0) + 2 * pr; ++row)
            for (int x = 0; x < w; ++x) {
              float sb = 0, sa = 0;
              for (int i = std::max(0, x - pr); i <= std::min(w - 1, x + pr); ++i) {
                sb += dist_b[size_t(row) * w + i];
                sa += dist_a[size_t(row) * w + i];
              }
              hsum_b[size_t(row) * w + x] = sb;
              hsum_a[size_t(row) * w + x] = sa;
            }
          // Vertical patch sums, weights, accumulation.
          for (int y = y0; y < y1; ++y) {
            const int qy = y + oy;
            if (qy < 0 || qy >= h) continue;
            for (int x = 0; x < w; ++x) {
              const int qx = x + ox;
              if (qx < 0 || qx >= w) continue;
              const size_t p = size_t(y) * w + x, q = size_t(qy) * w + qx;
              if (f.hit[p] != f.hit[q]) continue;  // sky and surfaces never mix
              float feature = 1.0f;
              if (f.hit[p] && q != p && params.feature_weights)
                feature = f.weight(p, q, ox, oy, params.sigma_normal, params.sigma_depth,
                                   params.sigma_albedo);
              if (feature < Features::kNegligible) continue;
              float db = 0, da = 0;
              for (int j = 0; j <= 2 * pr; ++j) {
                db += hsum_b[size_t(y - y0 + j) * w + x];
                da += hsum_a[size_t(y - y0 + j) * w + x];
              }
              const float weight_a =
                  std::min(feature, Features::expNegative(std::max(0.0f, db * patch_norm)));
              const float weight_b =
                  std::min(feature, Features::expNegative(std::max(0.0f, da * patch_norm)));
              const size_t t = size_t(y - y0) * w + x;
              for (int c = 0; c < 3; ++c) {
                sum_a[t * 3 + c] += weight_a * ua[q * 3 + c];
                sum_b[t * 3 + c] += weight_b * ub[q * 3 + c];
              }
              wsum_a[t] += weight_a;
              wsum_b[t] += weight_b;
              if (regress && f.hit[p]) {
                float x[kRegressors];
                regressors(f, p, q, x);
                addMoments(&moments_a[t * kMoments], x, &ua[q * 3], weight_a);
                addMoments(&moments_b[t * kMoments], x, &ub[q * 3], weight_b);
              }
            }
          }
        }
      for (int y = y0; y < y1; ++y)
        for (int x = 0; x < w; ++x) {
          const size_t t = size_t(y - y0) * w + x, p = size_t(y) * w + x;
          for (int c = 0; c < 3; ++c) {  // the centre's weight is 1: never zero
            out_a[p * 3 + c] = sum_a[t * 3 + c] / wsum_a[t];
            out_b[p * 3 + c] = sum_b[t * 3 + c] / wsum_b[t];
          }
          if (regress && f.hit[p]) {
            solveIntercept(&moments_a[t * kMoments], params.ridge, &out_a[p * 3]);
            solveIntercept(&moments_b[t * kMoments], params.ridge, &out_b[p * 3]);
          }
        }
    }
  };
  const int threads = std::clamp<int>(int(std::thread::hardware_concurrency()), 1, 8);
  std::vector<std::thread> pool;
  for (int t = 1; t < std::min(threads, tiles); ++t) pool.emplace_back(worker);
  worker();
  for (std::thread& thread : pool) thread.join();
}

void requireSameSize(const FloatImage& a, const FloatImage& b, const char* what) {
  if (a.width != b.width || a.height != b.height || a.rgba.size() != b.rgba.size())
    throw std::invalid_argument(std::string("nlm: ") + what + " size differs from the first half");
}

}  // namespace

FloatImage nlmDenoise(const SampleHalves& halves, const FloatImage& normal_depth,
                      const FloatImage& albedo_steps, const NlmParams& params,
                      SampleHalves* filtered) {
  requireSameSize(halves.a, halves.b, "second half");
  requireSameSize(halves.a, normal_depth, "normal/depth");
  requireSameSize(halves.a, albedo_steps, "albedo");
  const double n_a = halves.samples_a, n_b = halves.samples_b;
  if (!(n_a > 0 && n_b > 0)) throw std::invalid_argument("nlm: needs samples in both halves");
  const int w = int(halves.a.width), h = int(halves.a.height);
  const Features f(normal_depth, albedo_steps);
  SampleHalves clamped;
  if (params.clamp_fireflies) {
    clamped = halves;
    clampFireflies(clamped, params.fireflies);
  }
  const SampleHalves& input = params.clamp_fireflies ? clamped : halves;
  const Plane a = rgbOf(input.a), b = rgbOf(input.b);

  Plane var_a, var_b, out_a, out_b;
  guideVariances(a, b, w, h, params.variance_radius, n_a, n_b, var_a, var_b);
  crossFilter(a, b, a, b, var_a, var_b, f, params.k_first, params,
              params.regression && params.passes == 1, out_a, out_b);
  for (int pass = 1; pass < params.passes; ++pass) {
    // The previous pass's halves guide the next: less noise, better weights.
    const Plane guide_a = std::move(out_a), guide_b = std::move(out_b);
    guideVariances(guide_a, guide_b, w, h, params.variance_radius, n_a, n_b, var_a, var_b);
    const bool last = pass + 1 == params.passes;
    if (!last || params.select_k.empty()) {
      crossFilter(a, b, guide_a, guide_b, var_a, var_b, f, params.k_second, params,
                  params.regression && last, out_a, out_b);
      continue;
    }
    // Several strengths, chosen per pixel by their error against the other half.
    std::vector<Plane> candidates_a(params.select_k.size()), candidates_b(params.select_k.size());
    for (size_t i = 0; i < params.select_k.size(); ++i)
      crossFilter(a, b, guide_a, guide_b, var_a, var_b, f, params.select_k[i], params,
                  params.regression, candidates_a[i], candidates_b[i]);
    selectPerPixel(candidates_a, candidates_b, a, b, w, h, params.select, out_a, out_b);
  }

  FloatImage out(halves.a.width, halves.a.height, 1.0f);
  if (filtered) {
    *filtered = halves;
    for (size_t i = 0; i < out.pixelCount(); ++i)
      for (int c = 0; c < 3; ++c) {
        filtered->a.rgba[i * 4 + c] = out_a[i * 3 + c];
        filtered->b.rgba[i * 4 + c] = out_b[i * 3 + c];
      }
  }
  for (size_t i = 0; i < out.pixelCount(); ++i)
    for (int c = 0; c < 3; ++c)
      out.rgba[i * 4 + c] = float((n_a * out_a[i * 3 + c] + n_b * out_b[i * 3 + c]) / (n_a + n_b));
  return out;
}

}  // namespace legacy
}  // namespace sdfc
