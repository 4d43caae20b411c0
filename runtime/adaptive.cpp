#include "adaptive.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

#include "denoise_features.h"
#include "denoise_nlm.h"
#include "image_io.h"

namespace sdfc {
namespace {

using Clock = std::chrono::steady_clock;

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
  if (params.estimate == AdaptiveEstimate::Display) {
    // What an LDR metric sees: noise above white or deep in the dark costs little.
    // srgbEncode maps NaN and values <= 0 to 0.
    auto shown = [](float v) { return srgbEncode(std::min(v, 1.0f)); };
    std::vector<float> e(pixels);
    for (size_t i = 0; i < pixels; ++i) {
      float sum = 0;
      for (int c = 0; c < 3; ++c) {
        const float d = shown(first.a.rgba[i * 4 + c]) - shown(first.b.rgba[i * 4 + c]);
        sum += d * d;
      }
      e[i] = sum;
    }
    return boxMean(e, int(first.a.width), int(first.a.height), 1, params.box_radius);
  }
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

// A pixel's predicted cost per sample (AdaptiveParams::time_budget): its
// primary ray's march steps (attachment 2's w, the first phase's) plus
// `offset` x their image mean for the rest of the path (shadow and bounce rays,
// shading), which the steps do not see. Block means of it (allocateExtraSamples)
// follow lavapipe's lockstep lanes, which run as long as their slowest pixel.
std::vector<float> costPerSample(const FloatImage& albedo_steps, float offset) {
  const size_t pixels = albedo_steps.pixelCount();
  std::vector<float> cost(pixels);
  double mean = 0;
  for (size_t i = 0; i < pixels; ++i) {
    const float s = albedo_steps.rgba[i * 4 + 3];
    cost[i] = std::isfinite(s) ? std::max(0.0f, s) : 0.0f;
    mean += cost[i];
  }
  mean = pixels ? mean / double(pixels) : 0;
  const float add = float(std::max(0.0f, offset) * mean) + 1.0f;  // + 1: never free
  for (float& c : cost) c += add;
  return cost;
}

}  // namespace

std::vector<float> iterationsCost(const FloatImage& iterations, uint32_t w, uint32_t h) {
  const uint32_t iw = std::max<uint32_t>(iterations.width, 1), ih = std::max<uint32_t>(iterations.height, 1);
  std::vector<float> count(size_t(iw) * ih, 1.0f);
  for (size_t i = 0; i < count.size() && i < iterations.pixelCount(); ++i) {
    const float v = iterations.rgba[i * 4];
    count[i] = std::isfinite(v) ? std::max(1.0f, v) : 1.0f;
  }
  count = boxMean(count, int(iw), int(ih), 1, 1);
  std::vector<float> cost(size_t(w) * h);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x)
      cost[size_t(y) * w + x] = count[size_t(uint64_t(y) * ih / h) * iw + uint64_t(x) * iw / w];
  return cost;
}

namespace {

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
  if (name == "display") return AdaptiveEstimate::Display;
  return std::nullopt;
}

const char* adaptiveEstimateName(AdaptiveEstimate estimate) {
  switch (estimate) {
    case AdaptiveEstimate::Uniform: return "uniform";
    case AdaptiveEstimate::Variance: return "variance";
    case AdaptiveEstimate::Denoised: return "denoised";
    case AdaptiveEstimate::Display: return "display";
  }
  return "?";
}

std::vector<uint32_t> allocateExtraSamples(const std::vector<float>& weight, uint32_t w, uint32_t h,
                                           uint32_t block, float power, uint32_t extra_half,
                                           uint32_t cap_half, const std::vector<float>& cost) {
  block = std::max<uint32_t>(block, 1);
  cap_half = std::max(cap_half, extra_half);  // the budget always fits
  const uint32_t bw = (w + block - 1) / block, bh = (h + block - 1) / block;
  const size_t blocks = size_t(bw) * bh;
  std::vector<double> bweight(blocks, 0.0), bcost(blocks, 0.0);
  std::vector<uint32_t> bpixels(blocks, 0);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      const size_t b = size_t(y / block) * bw + x / block, i = size_t(y) * w + x;
      const double v = std::max(0.0f, weight[i]);
      bweight[b] = std::max(bweight[b], std::isfinite(v) ? v : 0.0);
      if (!cost.empty()) bcost[b] += cost[i];
      ++bpixels[b];
    }
  // Costs relative to their mean; all equal (or none): exactly 1, so the
  // arithmetic below is the samples budget's bit for bit.
  double cost_sum = 0;
  for (size_t b = 0; b < blocks; ++b) {
    bcost[b] = bpixels[b] ? bcost[b] / bpixels[b] : 0.0;
    if (!(bcost[b] > 0) || !std::isfinite(bcost[b])) bcost[b] = 0;
    cost_sum += bcost[b] * bpixels[b];
  }
  const double cost_mean = cost_sum / double(size_t(w) * h);
  bool equal = cost_mean > 0;
  for (size_t b = 0; b < blocks && equal; ++b) equal = bcost[b] == bcost[0];
  for (double& c : bcost) c = equal || !(cost_mean > 0) ? 1.0 : std::max(c / cost_mean, 1e-3);
  double mean = 0;
  for (size_t b = 0; b < blocks; ++b) {
    // Minimising sum e / n at a fixed sum c n gives n ~ sqrt(e / c) (Lagrange).
    bweight[b] = std::pow(bweight[b] / bcost[b], double(power));
    mean += bweight[b] * bpixels[b];
  }
  mean /= double(size_t(w) * h);
  // A floor keeps the allocation defined where every estimate is 0 (uniform then).
  for (double& v : bweight) v += mean > 0 ? 1e-3 * mean : 1.0;
  // The budget in cost: a uniform extra_half's (sum of cost = the pixel count).
  double pixel_cost = 0;
  for (size_t b = 0; b < blocks; ++b) pixel_cost += bcost[b] * bpixels[b];
  const double budget = double(extra_half) * (equal ? double(size_t(w) * h) : pixel_cost);
  auto spent = [&](double s) {
    double total = 0;
    for (size_t b = 0; b < blocks; ++b)
      total += std::min(double(cap_half), s * bweight[b]) * bpixels[b] * bcost[b];
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
  double given = 0;
  for (size_t b = 0; b < blocks; ++b) {
    const double target = std::min(double(cap_half), lo * bweight[b]);
    bcount[b] = uint32_t(std::floor(target));
    remainder[b] = target - bcount[b];
    given += double(bcount[b]) * bpixels[b] * bcost[b];
  }
  // What is left, in pixel-samples of cost 1 (exact integers when costs are equal).
  double left = std::max(0.0, budget - given);
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
      if (!(left > 0)) break;
      if (bcount[b] >= cap_half) continue;
      const uint32_t bx = uint32_t(b % bw) * block, by = uint32_t(b / bw) * block;
      // Pixels of this block the rest pays for (whole ones only).
      const uint64_t take =
          std::min<uint64_t>(uint64_t(std::floor(left / bcost[b] + 1e-9)), bpixels[b]);
      uint64_t n = 0;
      for (uint32_t y = by; y < std::min(h, by + block) && n < take; ++y)
        for (uint32_t x = bx; x < std::min(w, bx + block) && n < take; ++x, ++n) ++out[size_t(y) * w + x];
      ++bcount[b];
      left -= double(take) * bcost[b];
      progressed = take > 0;
      if (take < bpixels[b]) {  // a partial block: the budget is spent
        left = 0;
        break;
      }
    }
    if (!progressed) break;
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
  // The draws' hierarchy visits as the renderer's own passes get them.
  RenderSettings visits_settings = settings;
  visits_settings.loop_cap = renderer.loopCap();
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
  const std::vector<float> cost =
      !params.time_budget || uniform ? std::vector<float>()
      : params.cost_per_sample.size() == pixels ? params.cost_per_sample
                                                : costPerSample(out.albedo_steps, params.cost_offset);
  const std::vector<uint32_t> extra =
      uniform ? std::vector<uint32_t>(pixels, extra_half)
              : allocateExtraSamples(error, w, h, params.block, params.power, extra_half, cap_half,
                                     cost);
  if (!cost.empty()) {
    double spent = 0, uniform_cost = 0, samples = 0;
    for (size_t i = 0; i < pixels; ++i) {
      spent += double(cost[i]) * extra[i];
      uniform_cost += double(cost[i]) * extra_half;
      samples += extra[i];
    }
    st.predicted_cost_ratio = uniform_cost > 0 ? spent / uniform_cost : 1;
    st.sample_ratio = extra_half > 0 ? samples / (double(extra_half) * pixels) : 1;
  }
  st.estimate_seconds = secondsSince(estimate_start);

  // Phase 2: rounds of at most per_round samples a pixel, half a then half b.
  const auto extra_start = Clock::now();
  const bool jittered = settings.jittered_aovs;
  RenderSettings extra_settings = settings;
  extra_settings.spp = std::max<uint32_t>(1, *std::max_element(extra.begin(), extra.end()));
  const uint32_t per_round = chooseSamplesPerPass(extra_settings);
  Accumulation frame = renderer.startAccumulation(camera, settings, false);
  frame.params.tile_x = 0;
  frame.params.skip_aov_ray = jittered ? renderer.jitteredAovMode(settings) : 1u;
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
        buildDraws(count, first_index, w, y0, rows, frame.params, visits_settings, draws);
        if (draws.empty()) continue;
        st.draws += draws.size();
        const float* pass = renderer.runDraws(w, band_rows, rows, draws, settings.pass_timeout_seconds,
                                              jittered ? kReadAll : kReadColor);
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
  uint64_t extra_total = 0;  // the mean count (a time budget's differs from spp)
  for (size_t i = 0; i < pixels; ++i) {
    extra_total += done[i];
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
  out.samples_done =
      interrupted ? 2 * first_half
                  : 2 * (first_half + uint32_t((extra_total + pixels / 2) / std::max<size_t>(pixels, 1)));
  out.interrupted = interrupted;
  out.passes = a.passes + b.passes + 2 * st.rounds;
  out.seconds = secondsSince(start);
  halves->a = std::move(a.color);
  halves->b = std::move(b.color);
  halves->samples_a = halves->samples_b = out.samples_done / 2;
  reportFinished(progress, out.samples_done, n, out.passes, out.seconds);
  return out;
}

}  // namespace sdfc
