#include "denoise.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <thread>

namespace sdfc {
namespace {

float squaredDistance3(const float* a, const float* b) {
  const float dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
  return dx * dx + dy * dy + dz * dz;
}

// Guide values of one pixel, gathered once.
struct Guide {
  const float* normal_depth;
  const float* albedo;
  bool hit;
};

}  // namespace

std::optional<Denoiser> parseDenoiser(std::string_view name) {
  if (name == "none" || name == "off") return Denoiser::None;
  if (name == "bilateral") return Denoiser::Bilateral;
  if (name == "atrous" || name == "a-trous" || name == "a_trous") return Denoiser::ATrous;
  if (name == "svgf") return Denoiser::Svgf;
  if (name == "nlm") return Denoiser::Nlm;
  if (name == "nlr") return Denoiser::Nlr;
  if (name == "nlr-fast") return Denoiser::NlrFast;
  return std::nullopt;
}

const char* denoiserName(Denoiser denoiser) {
  switch (denoiser) {
    case Denoiser::None: return "none";
    case Denoiser::Bilateral: return "bilateral";
    case Denoiser::ATrous: return "atrous";
    case Denoiser::Svgf: return "svgf";
    case Denoiser::Nlm: return "nlm";
    case Denoiser::Nlr: return "nlr";
    case Denoiser::NlrFast: return "nlr-fast";
  }
  return "?";
}

FloatImage bilateralFilter(const FloatImage& color, const BilateralParams& params) {
  FloatImage out = color;
  const int w = int(color.width), h = int(color.height), r = std::max(params.radius, 0);
  const float spatial_scale = -0.5f / (params.sigma_spatial * params.sigma_spatial);
  const float range_scale = -0.5f / (params.sigma_range * params.sigma_range);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float* centre = color.at(uint32_t(x), uint32_t(y));
      double sum[3] = {0, 0, 0}, weight_sum = 0;
      for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx) {
          const int qx = x + dx, qy = y + dy;
          if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;  // renormalised below
          const float* q = color.at(uint32_t(qx), uint32_t(qy));
          const float weight = std::exp(spatial_scale * float(dx * dx + dy * dy) +
                                        range_scale * squaredDistance3(centre, q));
          for (int c = 0; c < 3; ++c) sum[c] += double(weight) * q[c];
          weight_sum += weight;
        }
      float* o = out.at(uint32_t(x), uint32_t(y));
      for (int c = 0; c < 3; ++c) o[c] = float(sum[c] / weight_sum);  // centre weight is 1
    }
  return out;
}

FloatImage atrousFilter(const FloatImage& color, const FloatImage& normal_depth,
                        const FloatImage& albedo_steps, const ATrousParams& params) {
  requireSameSize(color, normal_depth, "denoise: normal/depth size differs from colour");
  requireSameSize(color, albedo_steps, "denoise: albedo size differs from colour");
  const int w = int(color.width), h = int(color.height);
  constexpr float kAlbedoFloor = 1e-3f;  // keeps black albedo from dividing by zero
  auto isHit = [&](size_t i) { return normal_depth.rgba[i * 4 + 3] >= 0.0f; };
  auto demodulator = [&](size_t i, int c) {
    if (!params.demodulate_albedo || !isHit(i)) return 1.0f;
    return std::max(albedo_steps.rgba[i * 4 + c], kAlbedoFloor);
  };

  // Work on demodulated colour (irradiance): texture detail is not noise.
  FloatImage current = color;
  for (size_t i = 0; i < current.pixelCount(); ++i)
    for (int c = 0; c < 3; ++c) current.rgba[i * 4 + c] /= demodulator(i, c);
  FloatImage next = current;

  // B3-spline taps (1, 4, 6, 4, 1) / 16, as in Dammertz et al. 2010.
  constexpr float kKernel[5] = {1.0f / 16, 1.0f / 4, 3.0f / 8, 1.0f / 4, 1.0f / 16};
  const float inv_normal2 = 1.0f / (params.sigma_normal * params.sigma_normal);
  const float inv_albedo2 = 1.0f / (params.sigma_albedo * params.sigma_albedo);
  float sigma_color = params.sigma_color;
  for (int iteration = 0; iteration < params.iterations; ++iteration) {
    const int step = 1 << iteration;
    const float inv_color2 = 1.0f / (sigma_color * sigma_color);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const size_t p = size_t(y) * w + x;
        const float* cp = &current.rgba[p * 4];
        const float* np = &normal_depth.rgba[p * 4];
        const float* ap = &albedo_steps.rgba[p * 4];
        const bool hit_p = isHit(p);
        double sum[3] = {0, 0, 0}, weight_sum = 0;
        for (int j = -2; j <= 2; ++j)
          for (int i = -2; i <= 2; ++i) {
            const int qx = x + i * step, qy = y + j * step;
            if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
            const size_t q = size_t(qy) * w + qx;
            if (isHit(q) != hit_p) continue;  // never blur sky into surfaces
            const float* cq = &current.rgba[q * 4];
            float exponent = squaredDistance3(cp, cq) * inv_color2;
            if (hit_p) {
              const float* nq = &normal_depth.rgba[q * 4];
              exponent += squaredDistance3(np, nq) * inv_normal2;
              const float tap_distance = float(step) * std::sqrt(float(i * i + j * j));
              if (tap_distance > 0) {
                const float relative = std::fabs(np[3] - nq[3]) /
                                       (std::max(np[3], 1e-6f) * tap_distance * params.sigma_depth);
                exponent += relative * relative;
              }
              exponent += squaredDistance3(ap, &albedo_steps.rgba[q * 4]) * inv_albedo2;
            }
            const float weight = kKernel[i + 2] * kKernel[j + 2] * std::exp(-exponent);
            for (int c = 0; c < 3; ++c) sum[c] += double(weight) * cq[c];
            weight_sum += weight;
          }
        float* o = &next.rgba[p * 4];
        for (int c = 0; c < 3; ++c) o[c] = float(sum[c] / weight_sum);  // centre tap always counts
      }
    std::swap(current, next);
    sigma_color *= 0.5f;  // noise shrinks each level (Dammertz et al. 2010, sec. 3)
  }

  for (size_t i = 0; i < current.pixelCount(); ++i) {
    for (int c = 0; c < 3; ++c) current.rgba[i * 4 + c] *= demodulator(i, c);
    current.rgba[i * 4 + 3] = color.rgba[i * 4 + 3];
  }
  return current;
}

double predictedDenoiseSeconds(Denoiser denoiser, size_t pixels, size_t select_strengths) {
  // CPU seconds per million pixels (docs/denoise.md, 640x360 on this project's
  // 2-core machine; the passes' share for --denoise-select).
  double per_megapixel = 0;
  switch (denoiser) {
    case Denoiser::None: return 0;
    case Denoiser::Bilateral: per_megapixel = 0.4; break;
    case Denoiser::ATrous: per_megapixel = 1.0; break;
    case Denoiser::Svgf: per_megapixel = 2.8; break;
    case Denoiser::Nlm: per_megapixel = 1.2; break;
    case Denoiser::Nlr: per_megapixel = 1.6; break;
    case Denoiser::NlrFast: per_megapixel = 0.6; break;  // bench/results/ANIM_DENOISE.md (33 CPU ms at 320x180)
  }
  if (select_strengths > 1 && (denoiser == Denoiser::Nlm || denoiser == Denoiser::Nlr || denoiser == Denoiser::NlrFast))
    per_megapixel *= (1.0 + 2.5 * double(select_strengths)) / 3.5;
  const int threads = std::clamp<int>(int(std::thread::hardware_concurrency()), 1, 8);
  return per_megapixel * double(pixels) * 1e-6 / threads;
}

bool needsVariance(Denoiser denoiser) {
  return denoiser == Denoiser::Svgf || denoiser == Denoiser::Nlm || denoiser == Denoiser::Nlr ||
         denoiser == Denoiser::NlrFast;
}

bool wantsJitteredAovs(Denoiser denoiser) { return denoiser == Denoiser::Nlr || denoiser == Denoiser::NlrFast; }
bool wantsSpecularAovs(Denoiser denoiser) { return denoiser == Denoiser::Nlr || denoiser == Denoiser::NlrFast; }

FloatImage denoise(Denoiser denoiser, const FloatImage& color, const FloatImage& normal_depth,
                   const FloatImage& albedo_steps, const SampleHalves* halves,
                   const std::vector<float>& select_strengths, const DenoiseControl& control) {
  if (needsVariance(denoiser) && (!halves || halves->samples_a == 0 || halves->samples_b == 0))
    throw std::invalid_argument(std::string("denoise: ") + denoiserName(denoiser) +
                                " needs two half-sample renders");
  switch (denoiser) {
    case Denoiser::Svgf: {
      SvgfParams params;
      params.interrupt = control.interrupt;
      params.progress = control.progress;
      return svgfDenoise(*halves, normal_depth, albedo_steps, params);
    }
    case Denoiser::Nlm:
    case Denoiser::Nlr:
    case Denoiser::NlrFast: {
      NlmParams params = denoiser == Denoiser::Nlr ? nlrParams() : denoiser == Denoiser::NlrFast ? nlrFastParams() : NlmParams();
      params.select_k = select_strengths;
      params.interrupt = control.interrupt;
      params.progress = control.progress;
      return nlmDenoise(*halves, normal_depth, albedo_steps, params);
    }
    case Denoiser::Bilateral: return bilateralFilter(color);
    case Denoiser::ATrous: return atrousFilter(color, normal_depth, albedo_steps);
    case Denoiser::None: break;
  }
  return color;
}

}  // namespace sdfc
