#include "adaptive.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

#include "denoise_features.h"
#include "denoise_nlm.h"

namespace sdfc {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// relMSE's denominator: a pixel's squared error relative to its value.
constexpr float kRelativeFloor = 0.01f;

// Per-pixel relative squared difference of x against y (rgb of 4-float pixels),
// over the reference value m; box-averaged.
std::vector<float> relativeSquared(const FloatImage& x, const FloatImage& y, const FloatImage& m,
                                   int radius) {
  std::vector<float> e(x.pixelCount());
  for (size_t i = 0; i < e.size(); ++i) {
    float sum = 0;
    for (int c = 0; c < 3; ++c) {
      const float d = x.rgba[i * 4 + c] - y.rgba[i * 4 + c], v = m.rgba[i * 4 + c];
      sum += d * d / (v * v + kRelativeFloor);
    }
    e[i] = std::isfinite(sum) ? sum : 0.0f;
  }
  return boxMean(e, int(x.width), int(x.height), 1, radius);
}

FloatImage averageOf(const FloatImage& a, const FloatImage& b) {
  FloatImage m = a;
  for (size_t i = 0; i < m.rgba.size(); ++i) m.rgba[i] = 0.5f * (a.rgba[i] + b.rgba[i]);
  return m;
}

// The first phase's per-pixel error estimate (AdaptiveEstimate).
std::vector<float> estimateError(const RenderOutput& merged, const SampleHalves& first,
                                 bool jittered_aovs, const AdaptiveParams& params) {
  const size_t pixels = first.a.pixelCount();
  if (params.estimate == AdaptiveEstimate::Uniform) return std::vector<float>(pixels, 1.0f);
  if (params.estimate == AdaptiveEstimate::Variance) {
    // E[(a - b)^2] = Var a + Var b: proportional to the variance of the mean.
    return relativeSquared(first.a, first.b, averageOf(first.a, first.b), params.box_radius);
  }
  // Denoised: nlr filters each half with weights from the other; filtered half a
  // against raw half b estimates MSE(f_a) + Var b (denoise_select.h), and
  // Var b is half of E[(a - b)^2].
  RenderOutput features = merged;
  SampleHalves halves = first;
  if (jittered_aovs) resolveJitteredAovs(features, &halves);
  SampleHalves filtered;
  nlmDenoise(halves, features.normal_depth, features.albedo_steps, nlrParams(), &filtered);
  const FloatImage m = averageOf(filtered.a, filtered.b);
  const std::vector<float> ea = relativeSquared(filtered.a, halves.b, m, params.box_radius);
  const std::vector<float> eb = relativeSquared(filtered.b, halves.a, m, params.box_radius);
  const std::vector<float> noise = relativeSquared(halves.a, halves.b, m, params.box_radius);
  std::vector<float> e(pixels);
  for (size_t i = 0; i < pixels; ++i)
    e[i] = std::max(0.0f, 0.5f * (ea[i] + eb[i]) - 0.5f * noise[i]);
  return e;
}

// Rectangles of equal (count, first index) in rows [y0, y0 + rows): each row's
// runs, merged downwards with the same run of the row above.
struct Run {
  uint32_t x0, x1, count, base;
  size_t draw;
};

void buildDraws(const std::vector<uint32_t>& count, const std::vector<uint32_t>& base, uint32_t w,
                uint32_t y0, uint32_t rows, const gpu::FrameParams& frame,
                const RenderSettings& settings, std::vector<PassDraw>& draws) {
  draws.clear();
  std::vector<Run> above, here;
  for (uint32_t y = y0; y < y0 + rows; ++y) {
    here.clear();
    size_t k = 0;  // two-pointer into `above` (both sorted by x0)
    for (uint32_t x = 0; x < w;) {
      const size_t i = size_t(y) * w + x;
      uint32_t x1 = x + 1;
      while (x1 < w && count[i + x1 - x] == count[i] && base[i + x1 - x] == base[i]) ++x1;
      if (count[i] > 0) {
        Run run{x, x1, count[i], base[i], 0};
        while (k < above.size() && above[k].x0 < x) ++k;
        if (k < above.size() && above[k].x0 == x && above[k].x1 == x1 &&
            above[k].count == run.count && above[k].base == run.base) {
          run.draw = above[k].draw;
          ++draws[run.draw].rect.extent.height;
        } else {
          PassDraw draw;
          draw.rect = {{int32_t(x), int32_t(y - y0)}, {x1 - x, 1}};
          draw.params = frame;
          draw.params.sample_base = run.base;
          draw.params.sample_count = run.count;
          draw.params.traversal_visits = traversalVisitsFor(settings, run.count);
          run.draw = draws.size();
          draws.push_back(draw);
        }
        here.push_back(run);
      }
      x = x1;
    }
    std::swap(above, here);
  }
}

}  // namespace

std::optional<AdaptiveEstimate> parseAdaptiveEstimate(std::string_view name) {
  if (name == "uniform") return AdaptiveEstimate::Uniform;
  if (name == "variance") return AdaptiveEstimate::Variance;
  if (name == "denoised") return AdaptiveEstimate::Denoised;
  return std::nullopt;
}

const char* adaptiveEstimateName(AdaptiveEstimate estimate) {
  switch (estimate) {
    case AdaptiveEstimate::Uniform: return "uniform";
    case AdaptiveEstimate::Variance: return "variance";
    case AdaptiveEstimate::Denoised: return "denoised";
  }
  return "?";
}

std::vector<uint32_t> allocateExtraSamples(const std::vector<float>& weight, uint32_t w, uint32_t h,
                                           uint32_t block, float power, uint32_t extra_half,
                                           uint32_t cap_half) {
  block = std::max<uint32_t>(block, 1);
  cap_half = std::max(cap_half, extra_half);  // the budget always fits
  const uint32_t bw = (w + block - 1) / block, bh = (h + block - 1) / block;
  const size_t blocks = size_t(bw) * bh;
  std::vector<double> bweight(blocks, 0.0);
  std::vector<uint32_t> bpixels(blocks, 0);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      const size_t b = size_t(y / block) * bw + x / block;
      const double v = std::max(0.0f, weight[size_t(y) * w + x]);
      bweight[b] = std::max(bweight[b], std::isfinite(v) ? v : 0.0);
      ++bpixels[b];
    }
  double mean = 0;
  for (size_t b = 0; b < blocks; ++b) {
    bweight[b] = std::pow(bweight[b], double(power));
    mean += bweight[b] * bpixels[b];
  }
  mean /= double(size_t(w) * h);
  // A floor keeps the allocation defined where every estimate is 0 (uniform then).
  for (double& v : bweight) v += mean > 0 ? 1e-3 * mean : 1.0;
  const double budget = double(extra_half) * double(size_t(w) * h);
  auto spent = [&](double s) {
    double total = 0;
    for (size_t b = 0; b < blocks; ++b) total += std::min(double(cap_half), s * bweight[b]) * bpixels[b];
    return total;
  };
  // Water-filling: the scale whose capped targets spend the budget (bisection;
  // `lo` never overspends, so the floors below stay within it).
  double lo = 0, hi = 1;
  while (spent(hi) < budget && hi < 1e30) hi *= 2;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (spent(mid) <= budget ? lo : hi) = mid;
  }
  std::vector<uint32_t> bcount(blocks);
  std::vector<double> remainder(blocks);
  uint64_t given = 0;
  for (size_t b = 0; b < blocks; ++b) {
    const double target = std::min(double(cap_half), lo * bweight[b]);
    bcount[b] = uint32_t(std::floor(target));
    remainder[b] = target - bcount[b];
    given += uint64_t(bcount[b]) * bpixels[b];
  }
  const uint64_t total = uint64_t(extra_half) * w * h;
  uint64_t left = total - std::min(given, total);
  // The rest, one sample a pixel, to whole blocks by largest remainder; the last
  // part of a block to a prefix of its pixels.
  std::vector<size_t> order(blocks);
  std::iota(order.begin(), order.end(), size_t(0));
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t x, size_t y) { return remainder[x] > remainder[y]; });
  std::vector<uint32_t> out(size_t(w) * h);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) out[size_t(y) * w + x] = bcount[size_t(y / block) * bw + x / block];
  while (left > 0) {
    bool progressed = false;
    for (size_t b : order) {
      if (left == 0) break;
      if (bcount[b] >= cap_half) continue;
      const uint32_t bx = uint32_t(b % bw) * block, by = uint32_t(b / bw) * block;
      const uint64_t take = std::min<uint64_t>(left, bpixels[b]);
      uint64_t n = 0;
      for (uint32_t y = by; y < std::min(h, by + block) && n < take; ++y)
        for (uint32_t x = bx; x < std::min(w, bx + block) && n < take; ++x, ++n) ++out[size_t(y) * w + x];
      ++bcount[b];
      left -= take;
      progressed = true;
      if (take < bpixels[b]) break;  // a partial block: the budget is spent
    }
    if (!progressed) break;  // cannot happen: cap_half >= extra_half
  }
  return out;
}

RenderOutput renderAdaptive(Renderer& renderer, const CameraDesc& camera,
                            const RenderSettings& settings, const AdaptiveParams& params,
                            SampleHalves* halves, AdaptiveStats* stats,
                            const ProgressCallback& progress, const std::atomic<bool>* interrupt) {
  AdaptiveStats local_stats;
  AdaptiveStats& st = stats ? *stats : local_stats;
  st = AdaptiveStats();
  if (settings.view != gpu::kViewBeauty || settings.spp < 4)
    return renderHalves(renderer, camera, settings, halves, progress, interrupt);
  const auto start = Clock::now();
  const uint32_t n = settings.spp;
  const uint32_t half = n / 2;  // per half on average (an odd spp drops one sample)
  // First phase per half: the share, at least 1, at most all.
  const uint32_t first_half = std::clamp<uint32_t>(
      uint32_t(std::lround(double(params.first_share) * n / 2)), 1, half);
  const uint32_t extra_half = half - first_half;
  const bool uniform = params.estimate == AdaptiveEstimate::Uniform;
  // Each half owns an index range long enough for its most-sampled pixel: half b
  // starts after it (for a uniform allocation at n/2, as renderHalves).
  const uint32_t cap_total_half =
      uniform ? half : std::max(half, uint32_t(std::floor(double(params.cap) * first_half)));
  const uint32_t cap_half = cap_total_half - first_half;
  const uint32_t base_b = settings.first_sample + first_half + cap_half;

  // Phase 1: uniform halves, exact sums kept.
  RenderSettings first_a = settings;
  first_a.spp = first_half;
  first_a.keep_sums = true;
  RenderSettings first_b = first_a;
  first_b.first_sample = base_b;
  RenderOutput a = renderer.render(camera, first_a, progress, interrupt);
  RenderOutput b;
  if (!a.interrupted) b = renderer.render(camera, first_b, progress, interrupt);
  st.first_spp = 2 * first_half;
  st.first_seconds = secondsSince(start);
  if (a.interrupted || b.samples_done == 0) {
    *halves = SampleHalves();
    a.color_sums.clear();
    return a;
  }
  RenderOutput out = mergeRenders(a, b);
  SampleHalves first;
  first.a = a.color;
  first.b = b.color;
  first.samples_a = first.samples_b = first_half;

  const uint32_t w = settings.width, h = settings.height;
  const size_t pixels = size_t(w) * h;
  const auto estimate_start = Clock::now();
  const std::vector<float> error = estimateError(out, first, settings.jittered_aovs, params);
  const std::vector<uint32_t> extra =
      uniform ? std::vector<uint32_t>(pixels, extra_half)
              : allocateExtraSamples(error, w, h, params.block, params.power, extra_half, cap_half);
  st.estimate_seconds = secondsSince(estimate_start);

  // Phase 2: rounds of at most per_round samples a pixel, half a then half b.
  const auto extra_start = Clock::now();
  const bool jittered = settings.jittered_aovs;
  RenderSettings extra_settings = settings;
  extra_settings.spp = std::max<uint32_t>(1, *std::max_element(extra.begin(), extra.end()));
  const uint32_t per_round = chooseSamplesPerPass(extra_settings);
  Accumulation frame = renderer.startAccumulation(camera, settings, false);
  frame.params.tile_x = 0;
  frame.params.skip_aov_ray = jittered ? gpu::kAovJittered : 1u;
  const uint32_t band_rows = frame.band_rows;
  RenderOutput* phase[2] = {&a, &b};
  const uint32_t base[2] = {settings.first_sample + first_half, base_b + first_half};
  // Jittered AOVs as sums (mean x count), to add the extra samples' in.
  std::vector<double> aov[2];
  if (jittered)
    for (int k = 0; k < 2; ++k) {
      aov[k].resize(pixels * 8);
      for (size_t i = 0; i < pixels * 4; ++i) {
        aov[k][i] = double(phase[k]->normal_depth.rgba[i]) * first_half;
        aov[k][pixels * 4 + i] = double(phase[k]->albedo_steps.rgba[i]) * first_half;
      }
    }
  std::vector<uint32_t> done(pixels, 0), count(pixels), first_index(pixels);
  std::vector<PassDraw> draws;
  bool interrupted = false;
  for (;;) {
    bool any = false;
    for (size_t i = 0; i < pixels; ++i) {
      count[i] = std::min(per_round, extra[i] - done[i]);
      any = any || count[i] > 0;
    }
    if (!any) break;
    if (interrupt && interrupt->load()) {
      interrupted = true;
      break;
    }
    for (int k = 0; k < 2; ++k) {
      for (size_t i = 0; i < pixels; ++i) first_index[i] = base[k] + done[i];
      std::vector<SampleSum>& sum = phase[k]->color_sums;
      for (uint32_t y0 = 0; y0 < h; y0 += band_rows) {
        const uint32_t rows = std::min(band_rows, h - y0);
        frame.params.tile_y = y0;
        buildDraws(count, first_index, w, y0, rows, frame.params, settings, draws);
        if (draws.empty()) continue;
        st.draws += draws.size();
        const float* pass = renderer.runDraws(w, band_rows, rows, draws, settings.pass_timeout_seconds,
                                              jittered ? kAttachmentCount : 1);
        const float* nd = pass + renderer.targetImageFloats();
        const float* as = nd + renderer.targetImageFloats();
        for (size_t j = 0; j < size_t(rows) * w; ++j) {
          const size_t i = size_t(y0) * w + j;
          if (count[i] == 0) continue;
          for (int c = 0; c < 4; ++c) sum[i * 4 + c] += sampleTerm(pass[j * 4 + c], count[i]);
          if (jittered)
            for (int c = 0; c < 4; ++c) {
              aov[k][i * 4 + c] += double(nd[j * 4 + c]) * count[i];
              aov[k][pixels * 4 + i * 4 + c] += double(as[j * 4 + c]) * count[i];
            }
        }
      }
    }
    uint64_t total_done = 0;
    for (size_t i = 0; i < pixels; ++i) total_done += (done[i] += count[i]);
    ++st.rounds;
    if (progress) {
      ProgressInfo info;
      info.samples_done = uint32_t(2 * first_half + 2 * total_done / std::max<size_t>(pixels, 1));
      info.samples_total = n;
      info.passes_done = a.passes + b.passes + 2 * st.rounds;
      info.elapsed_seconds = secondsSince(start);
      info.eta_seconds = -1;
      progress(info);
    }
  }
  st.extra_seconds = secondsSince(extra_start);

  // Per-pixel means: each half over its own count, the merge over both.
  out.sample_counts.resize(pixels);
  FloatImage& color = out.color;
  for (size_t i = 0; i < pixels; ++i) {
    const uint32_t per_half = first_half + done[i];
    out.sample_counts[i] = 2 * per_half;
    st.max_spp = std::max(st.max_spp, 2 * per_half);
    for (int c = 0; c < 4; ++c) {
      const SampleSum sa = a.color_sums[i * 4 + c], sb = b.color_sums[i * 4 + c];
      a.color.rgba[i * 4 + c] = sampleMean(sa, per_half);
      b.color.rgba[i * 4 + c] = sampleMean(sb, per_half);
      // As mergeRenders: one rounding of the exact sums with keep_sums, else the
      // halves' double mean (renderHalves' image, bit for bit, when uniform).
      color.rgba[i * 4 + c] =
          settings.keep_sums
              ? sampleMean(sa + sb, 2 * uint64_t(per_half))
              : float((double(a.color.rgba[i * 4 + c]) + double(b.color.rgba[i * 4 + c])) * 0.5);
    }
    if (jittered)
      for (int c = 0; c < 4; ++c) {
        const double scale = 1.0 / (2.0 * per_half);
        out.normal_depth.rgba[i * 4 + c] = float((aov[0][i * 4 + c] + aov[1][i * 4 + c]) * scale);
        out.albedo_steps.rgba[i * 4 + c] =
            float((aov[0][pixels * 4 + i * 4 + c] + aov[1][pixels * 4 + i * 4 + c]) * scale);
      }
  }
  if (settings.keep_sums) {
    out.color_sums.resize(pixels * 4);
    for (size_t i = 0; i < pixels * 4; ++i) out.color_sums[i] = a.color_sums[i] + b.color_sums[i];
  } else {
    out.color_sums.clear();
  }
  out.samples_done = interrupted ? 2 * first_half : 2 * half;
  out.interrupted = interrupted;
  out.passes = a.passes + b.passes + 2 * st.rounds;
  out.seconds = secondsSince(start);
  halves->a = std::move(a.color);
  halves->b = std::move(b.color);
  halves->samples_a = halves->samples_b = out.samples_done / 2;
  if (progress) {
    ProgressInfo info;
    info.samples_done = out.samples_done;
    info.samples_total = n;
    info.passes_done = out.passes;
    info.elapsed_seconds = out.seconds;
    info.eta_seconds = 0;
    info.finished = true;
    progress(info);
  }
  return out;
}

}  // namespace sdfc
