#include "denoise_nlm.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
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
// sample counts n_a, n_b). boxMean's sums in its order, with the squares taken
// and the shares applied on the way (no planes between: 1.3 ms of a 320x180
// frame's 21 were their allocation and copies).
void guideVariances(const Plane& ga, const Plane& gb, int w, int h, int radius, double n_a,
                    double n_b, Plane& var_a, Plane& var_b) {
  const size_t n = size_t(w) * h;
  Plane row(n * 3);
  forEachRow(h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const int x0 = std::max(0, x - radius), x1 = std::min(w - 1, x + radius);
      for (int c = 0; c < 3; ++c) {
        float sum = 0;
        for (int q = x0; q <= x1; ++q) {
          const size_t i = (size_t(y) * w + q) * 3 + c;
          sum += (ga[i] - gb[i]) * (ga[i] - gb[i]);
        }
        row[(size_t(y) * w + x) * 3 + c] = sum / float(x1 - x0 + 1);
      }
    }
  });
  const float share_a = float(n_b / (n_a + n_b)), share_b = float(n_a / (n_a + n_b));
  var_a.resize(n * 3);
  var_b.resize(n * 3);
  forEachRow(h, [&](int y) {
    const int y0 = std::max(0, y - radius), y1 = std::min(h - 1, y + radius);
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
        float sum = 0;
        for (int q = y0; q <= y1; ++q) sum += row[(size_t(q) * w + x) * 3 + c];
        const float mean = sum / float(y1 - y0 + 1);
        const size_t i = (size_t(y) * w + x) * 3 + c;
        var_a[i] = share_a * mean;
        var_b[i] = share_b * mean;
      }
  });
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

// The pass's planes, each padded by `pad_x` pixels left and right and `pad_y`
// above and below so that the kernel's vector loads of a neighbour (up to the
// search and patch radii, and a vector's width, past the image) stay in memory.
// Not zeroed first: the image and the pads are written once (a frame of an
// animation fills 28 planes of 400 kB; zeroing them was a tenth of nlr-fast's time).
using PaddedPlane = std::unique_ptr<float[]>;
struct Padded {
  int w = 0, h = 0, pad_x = 0, pad_y = 0, stride = 0;
  Padded(int w_, int h_, int pad_x_, int pad_y_)
    : w(w_), h(h_), pad_x(pad_x_), pad_y(pad_y_), stride(w_ + 2 * pad_x_) {}
  size_t at(int x, int y) const { return size_t(y + pad_y) * stride + size_t(x + pad_x); }
  size_t size() const { return size_t(stride) * (h + 2 * pad_y); }
  static constexpr int kMostPlanes = 18;  // a pass's six rgb images
  // `count` planes: fill[k] outside the image, and within it what
  // row(y, planes) writes at at(x, y); the rows on every core.
  template <typename Row>
  void fill(PaddedPlane* out, int count, const float* fill, const Row& row) const {
    if (count > kMostPlanes) throw std::logic_error("nlm: too many planes at once");
    float* planes[kMostPlanes];
    for (int k = 0; k < count; ++k) {
      out[k].reset(new float[size()]);
      planes[k] = out[k].get();
    }
    forEachRow(h + 2 * pad_y, [&](int padded_y) {
      const int y = padded_y - pad_y;
      for (int k = 0; k < count; ++k) {
        float* line = planes[k] + size_t(padded_y) * stride;
        if (y < 0 || y >= h) {
          std::fill(line, line + stride, fill[k]);
        } else {
          std::fill(line, line + pad_x, fill[k]);
          std::fill(line + pad_x + w, line + stride, fill[k]);
        }
      }
      if (y >= 0 && y < h) row(y, planes);
    });
  }
  // The three channels of an rgb image each (0 outside): planes out[3 s + c].
  void rgbPlanes(const float* const* rgb, int images, PaddedPlane* out) const {
    const float zeros[kMostPlanes] = {};
    fill(out, 3 * images, zeros, [&](int y, float* const* planes) {
      for (int s = 0; s < images; ++s)
        for (int x = 0; x < w; ++x)
          for (int c = 0; c < 3; ++c) planes[3 * s + c][at(x, y)] = rgb[s][(size_t(y) * w + x) * 3 + c];
    });
  }
};

constexpr int kMaxRadius = 16;  // search windows up to 33 x 33
constexpr int kBlockRows = 16, kBlockCols = 80;

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

// The pass's features, padded, straight from the renderer's attachments (the
// values and slopes of Features, without its arrays between): the same for
// every pass of a denoise.
struct FeaturePlanes {
  // albedo (3), normal (3), depth, depth_dx, depth_dy, then hit (1 a surface,
  // 0 the sky, -1 outside the image).
  PaddedPlane albedo[3], normal[3], depth, depth_dx, depth_dy, hit;
  FeaturePlanes(const FloatImage& normal_depth, const FloatImage& albedo_steps, const Padded& layout) {
    PaddedPlane planes[10];
    const float fills[10] = {0, 0, 0, 0, 0, 0, 0, 0, 0, -1};
    const int w = layout.w, h = layout.h;
    const float* nd = normal_depth.rgba.data();
    const float* as = albedo_steps.rgba.data();
    auto depth_at = [nd](size_t q) { return nd[q * 4 + 3]; };
    auto hit_at = [nd](size_t q) { return nd[q * 4 + 3] >= 0.0f; };
    layout.fill(planes, 10, fills, [&](int y, float* const* out) {
      for (int x = 0; x < w; ++x) {
        const size_t i = size_t(y) * w + x, p = layout.at(x, y);
        for (int c = 0; c < 3; ++c) {
          out[c][p] = as[i * 4 + c];
          out[3 + c][p] = nd[i * 4 + c];
        }
        const bool surface = hit_at(i);
        out[6][p] = depth_at(i);
        out[7][p] = surface ? depthSlope(i, -1, 1, x > 0, x + 1 < w, depth_at, hit_at) : 0.0f;
        out[8][p] = surface ? depthSlope(i, -long(w), long(w), y > 0, y + 1 < h, depth_at, hit_at) : 0.0f;
        out[9][p] = surface ? 1.0f : 0.0f;
      }
    });
    for (int c = 0; c < 3; ++c) {
      albedo[c] = std::move(planes[c]);
      normal[c] = std::move(planes[3 + c]);
    }
    depth = std::move(planes[6]);
    depth_dx = std::move(planes[7]);
    depth_dy = std::move(planes[8]);
    hit = std::move(planes[9]);
  }
};

Padded layoutFor(int w, int h, const NlmParams& params) {
  const int r = params.radius, pr = std::max(params.patch_radius, 0);
  if (r < 0 || r > kMaxRadius || pr > kMaxRadius)
    throw std::invalid_argument("nlm: search radius " + std::to_string(r) + " or patch radius " +
                                std::to_string(pr) + " outside 0.." + std::to_string(kMaxRadius));
  // Rows: the radii reach no further (one row more: a vector read past the last
  // row's end stays in memory).
  return Padded(w, h, r + pr + 2 * kMostLanes, r + pr + 1);
}

// One pass: out_a = ua filtered with weights from guide gb, out_b = ub with
// weights from guide ga. Blocks of pixels on every core; returns false (the
// output unfinished) when params.interrupt was set. `progress` (if set) gets
// the pass's finished share now and then, from one thread at a time.
bool crossFilter(const Plane& ua, const Plane& ub, const Plane& ga, const Plane& gb,
                 const Plane& var_a, const Plane& var_b, int w, int h, const FeaturePlanes& fp,
                 float k, const NlmParams& params, bool regress, Plane& out_a, Plane& out_b,
                 const std::function<void(double)>& progress) {
  if (params.interrupt && params.interrupt->load()) return false;
  const Padded layout = layoutFor(w, h, params);
  // Each distinct plane once: the first pass's guides are the colours it filters.
  PaddedPlane planes[18];
  const Plane* sources[6] = {&ga, &gb, &var_a, &var_b, &ua, &ub};
  const bool guides_are_colours = &ga == &ua && &gb == &ub;
  const float* rgb[6];
  for (int s = 0; s < 6; ++s) rgb[s] = sources[s]->data();
  layout.rgbPlanes(rgb, guides_are_colours ? 4 : 6, planes);
  const int colours = guides_are_colours ? 0 : 4;
  out_a.assign(ua.size(), 0.0f);
  out_b.assign(ub.size(), 0.0f);
  PassData d{layout};
  for (int c = 0; c < 3; ++c) {
    d.guide_a[c] = planes[c].get();
    d.guide_b[c] = planes[3 + c].get();
    d.var_a[c] = planes[6 + c].get();
    d.var_b[c] = planes[9 + c].get();
    d.colour_a[c] = planes[3 * colours + c].get();
    d.colour_b[c] = planes[3 * (colours + 1) + c].get();
    d.albedo[c] = fp.albedo[c].get();
    d.normal[c] = fp.normal[c].get();
  }
  d.depth = fp.depth.get();
  d.depth_dx = fp.depth_dx.get();
  d.depth_dy = fp.depth_dy.get();
  d.hit = fp.hit.get();
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


}  // namespace

FloatImage nlmDenoise(const SampleHalves& halves, const FloatImage& normal_depth,
                      const FloatImage& albedo_steps, const NlmParams& params,
                      SampleHalves* filtered) {
  requireSameSize(halves.a, halves.b, "nlm: second half size differs from the first half");
  requireSameSize(halves.a, normal_depth, "nlm: normal/depth size differs from the first half");
  requireSameSize(halves.a, albedo_steps, "nlm: albedo size differs from the first half");
  const double n_a = halves.samples_a, n_b = halves.samples_b;
  if (!(n_a > 0 && n_b > 0)) throw std::invalid_argument("nlm: needs samples in both halves");
  const int w = int(halves.a.width), h = int(halves.a.height);
  auto stopped = [&] { return params.interrupt && params.interrupt->load(); };
  if (stopped()) return {};
  SampleHalves clamped;
  if (params.clamp_fireflies) {
    clamped = halves;
    clampFireflies(clamped, params.fireflies);
  }
  const SampleHalves& input = params.clamp_fireflies ? clamped : halves;
  const Plane a = rgbOf(input.a), b = rgbOf(input.b);
  if (stopped()) return {};

  const FeaturePlanes fp(normal_depth, albedo_steps, layoutFor(w, h, params));
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
  if (!crossFilter(a, b, a, b, var_a, var_b, w, h, fp, params.k_first, params,
                   params.regression && params.passes == 1, out_a, out_b, next()))
    return {};
  for (int pass = 1; pass < params.passes; ++pass) {
    // The previous pass's halves guide the next: less noise, better weights.
    const Plane guide_a = std::move(out_a), guide_b = std::move(out_b);
    guideVariances(guide_a, guide_b, w, h, params.variance_radius, n_a, n_b, var_a, var_b);
    const bool last = pass + 1 == params.passes;
    if (!last || params.select_k.empty()) {
      if (!crossFilter(a, b, guide_a, guide_b, var_a, var_b, w, h, fp, params.k_second, params,
                       params.regression && last, out_a, out_b, next()))
        return {};
      continue;
    }
    // Several strengths, chosen per pixel by their error against the other half.
    std::vector<Plane> candidates_a(params.select_k.size()), candidates_b(params.select_k.size());
    for (size_t i = 0; i < params.select_k.size(); ++i)
      if (!crossFilter(a, b, guide_a, guide_b, var_a, var_b, w, h, fp, params.select_k[i], params,
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
