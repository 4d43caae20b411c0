#include "denoise_nlm.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "denoise_features.h"
#include "denoise_select.h"

namespace sdfc {
namespace {

constexpr float kEpsilon = 1e-10f;  // Rousselle et al. 2012's epsilon: zero variance, zero reach

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

// The pass's planes, each padded by `pad` pixels on every side so that the
// kernel's vector loads of a neighbour (up to the search and patch radii, and
// a vector's width, past the image) stay in memory.
struct Padded {
  int w = 0, h = 0, pad = 0, stride = 0;
  Padded(int w_, int h_, int pad_) : w(w_), h(h_), pad(pad_), stride(w_ + 2 * pad_) {}
  size_t at(int x, int y) const { return size_t(y + pad) * stride + size_t(x + pad); }
  size_t size() const { return size_t(stride) * (h + 2 * pad); }
  // Channel c of an interleaved image of `channels` values a pixel; `fill` outside.
  Plane plane(const float* in, int channels, int c, float fill = 0.0f) const {
    Plane out(size(), fill);
    forEachRow(h, [&](int y) {
      for (int x = 0; x < w; ++x) out[at(x, y)] = in[(size_t(y) * w + x) * channels + c];
    });
    return out;
  }
  // The three channels of an rgb image (0 outside), in one pass over it.
  void planes(const float* rgb, Plane* out) const {
    for (int c = 0; c < 3; ++c) out[c].assign(size(), 0.0f);
    forEachRow(h, [&](int y) {
      for (int x = 0; x < w; ++x)
        for (int c = 0; c < 3; ++c) out[c][at(x, y)] = rgb[(size_t(y) * w + x) * 3 + c];
    });
  }
};

constexpr int kMaxRadius = 16;  // search windows up to 33 x 33
constexpr int kBlockRows = 16, kBlockCols = 64;

// What one pass reads and writes (the kernel's input).
struct PassData {
  Padded layout;
  const float* guide_a[3];
  const float* guide_b[3];
  const float* var_a[3];
  const float* var_b[3];
  const float* colour_a[3];
  const float* colour_b[3];
  const float* albedo[3];
  const float* normal[3];
  const float* depth;
  const float* depth_dx;
  const float* depth_dy;
  const float* hit;  // 1 a surface, 0 the sky, -1 outside the image
  float k2, patch_norm, ridge;
  float sigma_normal, sigma_depth, sigma_albedo;
  int radius, patch_radius;
  bool regress, feature_weights;
  float* out_a;  // rgb of every pixel, not padded
  float* out_b;
};

// A thread's work space, kept between blocks and passes.
struct Scratch {
  std::vector<float> dist_a, dist_b, hsum_a, hsum_b, weight_a, weight_b;
};

// Vector arguments of inlined functions only: no ABI to keep.
#pragma GCC diagnostic ignored "-Wpsabi"
namespace baseline {
constexpr int kLanes = 4;  // SSE2's (NEON's) 128 bits
#include "denoise_nlm_kernel.inc"
}  // namespace baseline
#if defined(__x86_64__)
#pragma GCC push_options
#pragma GCC target("avx2,fma")
namespace avx2 {
constexpr int kLanes = 8;
#include "denoise_nlm_kernel.inc"
}  // namespace avx2
#pragma GCC pop_options
#pragma GCC push_options
#pragma GCC target("avx512f,avx512vl,avx512dq,avx2,fma")
namespace avx512 {
constexpr int kLanes = 16;
#include "denoise_nlm_kernel.inc"
}  // namespace avx512
#pragma GCC pop_options
#endif
constexpr int kMostLanes = 16;

// Which kernel runs: 2 AVX-512, 1 AVX2 with FMA, 0 the baseline; the CPU's
// best, or less where SDFC_SIMD (baseline, avx2) asks (the tests run each).
int simdLevel() {
#if defined(__x86_64__)
  const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  const bool avx512 = avx2 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
                      __builtin_cpu_supports("avx512dq");
  int level = avx512 ? 2 : avx2 ? 1 : 0;
#else
  int level = 0;
#endif
  if (const char* asked = std::getenv("SDFC_SIMD")) {
    const std::string a = asked;
    if (a == "baseline") level = 0;
    if (a == "avx2") level = std::min(level, 1);
  }
  return level;
}

// The pass's features, padded: the same for every pass of a denoise.
struct FeaturePlanes {
  Plane albedo[3], normal[3], depth, depth_dx, depth_dy, hit;
  FeaturePlanes(const Features& f, const Padded& layout) {
    layout.planes(f.albedo.data(), albedo);
    layout.planes(f.normal.data(), normal);
    depth = layout.plane(f.depth.data(), 1, 0);
    depth_dx = layout.plane(f.depth_dx.data(), 1, 0);
    depth_dy = layout.plane(f.depth_dy.data(), 1, 0);
    hit.assign(layout.size(), -1.0f);
    forEachRow(f.height, [&](int y) {
      for (int x = 0; x < f.width; ++x) hit[layout.at(x, y)] = f.hit[size_t(y) * f.width + x] ? 1.0f : 0.0f;
    });
  }
};

Padded layoutFor(const Features& f, const NlmParams& params) {
  const int r = params.radius, pr = std::max(params.patch_radius, 0);
  if (r < 0 || r > kMaxRadius || pr > kMaxRadius)
    throw std::invalid_argument("nlm: search radius " + std::to_string(r) + " or patch radius " +
                                std::to_string(pr) + " outside 0.." + std::to_string(kMaxRadius));
  return Padded(f.width, f.height, r + pr + 2 * kMostLanes);
}

// One pass: out_a = ua filtered with weights from guide gb, out_b = ub with
// weights from guide ga. Blocks of pixels on every core; returns false (the
// output unfinished) when params.interrupt was set. `progress` (if set) gets
// the pass's finished share now and then, from one thread at a time.
bool crossFilter(const Plane& ua, const Plane& ub, const Plane& ga, const Plane& gb,
                 const Plane& var_a, const Plane& var_b, const Features& f, const FeaturePlanes& fp,
                 float k, const NlmParams& params, bool regress, Plane& out_a, Plane& out_b,
                 const std::function<void(double)>& progress) {
  const int w = f.width, h = f.height;
  if (params.interrupt && params.interrupt->load()) return false;
  const Padded layout = layoutFor(f, params);
  Plane planes[6][3];
  const Plane* sources[6] = {&ga, &gb, &var_a, &var_b, &ua, &ub};
  for (int s = 0; s < 6; ++s) layout.planes(sources[s]->data(), planes[s]);
  out_a.assign(ua.size(), 0.0f);
  out_b.assign(ub.size(), 0.0f);
  PassData d{layout};
  for (int c = 0; c < 3; ++c) {
    d.guide_a[c] = planes[0][c].data();
    d.guide_b[c] = planes[1][c].data();
    d.var_a[c] = planes[2][c].data();
    d.var_b[c] = planes[3][c].data();
    d.colour_a[c] = planes[4][c].data();
    d.colour_b[c] = planes[5][c].data();
    d.albedo[c] = fp.albedo[c].data();
    d.normal[c] = fp.normal[c].data();
  }
  d.depth = fp.depth.data();
  d.depth_dx = fp.depth_dx.data();
  d.depth_dy = fp.depth_dy.data();
  d.hit = fp.hit.data();
  d.k2 = k * k;
  d.radius = params.radius;
  d.patch_radius = std::max(params.patch_radius, 0);
  d.patch_norm = 1.0f / float((2 * d.patch_radius + 1) * (2 * d.patch_radius + 1));
  d.ridge = params.ridge;
  d.sigma_normal = params.sigma_normal;
  d.sigma_depth = params.sigma_depth;
  d.sigma_albedo = params.sigma_albedo;
  d.regress = regress;
  d.feature_weights = params.feature_weights;
  d.out_a = out_a.data();
  d.out_b = out_b.data();

  const int simd = simdLevel();
  const int blocks_x = (w + kBlockCols - 1) / kBlockCols, blocks_y = (h + kBlockRows - 1) / kBlockRows;
  const int blocks = blocks_x * blocks_y;
  std::atomic<bool> stopped{false};
  std::atomic<int> done{0};
  std::mutex report;  // progress is called by one thread at a time
  forEachRow(blocks, [&](int b) {
    if (params.interrupt && params.interrupt->load(std::memory_order_relaxed)) {
      stopped = true;
      return;
    }
    thread_local Scratch scratch;
    const int x0 = (b % blocks_x) * kBlockCols, y0 = (b / blocks_x) * kBlockRows;
    const int rows = std::min(kBlockRows, h - y0);
    const int cols = std::min(kBlockCols, w - x0);
#if defined(__x86_64__)
    if (simd >= 2)
      avx512::filterBlock(d, x0, y0, rows, cols, scratch);
    else if (simd == 1)
      avx2::filterBlock(d, x0, y0, rows, cols, scratch);
    else
#endif
      baseline::filterBlock(d, x0, y0, rows, cols, scratch);
    const int finished = ++done;
    if (progress && finished % std::max(1, blocks / 32) == 0) {
      std::lock_guard<std::mutex> lock(report);
      progress(double(finished) / blocks);
    }
  });
  return !stopped;
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
  auto stopped = [&] { return params.interrupt && params.interrupt->load(); };
  const Features f(normal_depth, albedo_steps);
  if (stopped()) return {};
  SampleHalves clamped;
  if (params.clamp_fireflies) {
    clamped = halves;
    clampFireflies(clamped, params.fireflies);
  }
  const SampleHalves& input = params.clamp_fireflies ? clamped : halves;
  const Plane a = rgbOf(input.a), b = rgbOf(input.b);
  if (stopped()) return {};

  const FeaturePlanes fp(f, layoutFor(f, params));
  // The share of the work each pass is (a regression pass costs kRegressCost
  // plain ones), for params.progress.
  constexpr double kRegressCost = 2.5;
  std::vector<double> costs;
  for (int pass = 0; pass < params.passes; ++pass) {
    const bool last = pass + 1 == params.passes;
    const int runs = last && pass > 0 && !params.select_k.empty() ? int(params.select_k.size()) : 1;
    for (int i = 0; i < runs; ++i) costs.push_back(params.regression && last ? kRegressCost : 1.0);
  }
  double total_cost = 0;
  for (double c : costs) total_cost += c;
  size_t run = 0;
  double cost_done = 0;
  // The next crossFilter's progress (and, once it has returned, its cost counted as done).
  auto next = [&]() -> std::function<void(double)> {
    if (run > 0) cost_done += costs[run - 1];
    const double cost = costs[std::min(run, costs.size() - 1)], before = cost_done;
    ++run;
    if (!params.progress) return {};
    return [&params, cost, before, total_cost](double share) {
      params.progress((before + share * cost) / total_cost);
    };
  };
  Plane var_a, var_b, out_a, out_b;
  guideVariances(a, b, w, h, params.variance_radius, n_a, n_b, var_a, var_b);
  if (!crossFilter(a, b, a, b, var_a, var_b, f, fp, params.k_first, params,
                   params.regression && params.passes == 1, out_a, out_b, next()))
    return {};
  for (int pass = 1; pass < params.passes; ++pass) {
    // The previous pass's halves guide the next: less noise, better weights.
    const Plane guide_a = std::move(out_a), guide_b = std::move(out_b);
    guideVariances(guide_a, guide_b, w, h, params.variance_radius, n_a, n_b, var_a, var_b);
    const bool last = pass + 1 == params.passes;
    if (!last || params.select_k.empty()) {
      if (!crossFilter(a, b, guide_a, guide_b, var_a, var_b, f, fp, params.k_second, params,
                       params.regression && last, out_a, out_b, next()))
        return {};
      continue;
    }
    // Several strengths, chosen per pixel by their error against the other half.
    std::vector<Plane> candidates_a(params.select_k.size()), candidates_b(params.select_k.size());
    for (size_t i = 0; i < params.select_k.size(); ++i)
      if (!crossFilter(a, b, guide_a, guide_b, var_a, var_b, f, fp, params.select_k[i], params,
                       params.regression, candidates_a[i], candidates_b[i], next()))
        return {};
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

}  // namespace sdfc
