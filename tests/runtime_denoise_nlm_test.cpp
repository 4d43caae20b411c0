// The dual-buffer NL-means denoiser: it removes noise, keeps edges the features
// mark, and is unbiased at convergence: with zero variance it is the identity, and
// its error falls to zero as the sample count rises (the noise it is given falls
// as 1/sqrt(n)) on a shadow edge that no feature marks.
#include <gtest/gtest.h>

#include <cmath>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "denoise.h"
#include "denoise_nlm.h"

namespace sdfc {
namespace {

constexpr uint32_t kSize = 48;

// One plane facing the camera at depth 5 (left half normal +z, right half +x
// when `split_normals`), grey albedo; the top `sky_rows` rows missed (depth -1).
void planeGuides(FloatImage& normal_depth, FloatImage& albedo, bool split_normals,
                 uint32_t sky_rows = 0) {
  normal_depth = FloatImage(kSize, kSize);
  albedo = FloatImage(kSize, kSize, 0.5f);
  for (uint32_t y = 0; y < kSize; ++y)
    for (uint32_t x = 0; x < kSize; ++x) {
      float* n = normal_depth.at(x, y);
      const bool right = split_normals && x >= kSize / 2;
      n[0] = right ? 1.0f : 0.0f;
      n[2] = right ? 0.0f : 1.0f;
      n[3] = y < sky_rows ? -1.0f : 5.0f;
    }
}

float stepTruth(uint32_t x) { return x < kSize / 2 ? 0.2f : 0.3f; }
float flatTruth(uint32_t) { return 0.25f; }

// Two independent halves of `samples` samples each of truth(x) with per-sample
// noise sigma (grey: one path, three channels).
SampleHalves noisyHalves(float sigma, uint32_t samples, float (*truth)(uint32_t), uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, sigma / std::sqrt(float(samples)));
  SampleHalves h;
  h.a = FloatImage(kSize, kSize, 1.0f);
  h.b = FloatImage(kSize, kSize, 1.0f);
  h.samples_a = h.samples_b = samples;
  for (uint32_t y = 0; y < kSize; ++y)
    for (uint32_t x = 0; x < kSize; ++x) {
      const float n_a = noise(rng), n_b = noise(rng);
      for (int c = 0; c < 3; ++c) {
        h.a.at(x, y)[c] = truth(x) + n_a;
        h.b.at(x, y)[c] = truth(x) + n_b;
      }
    }
  return h;
}

FloatImage meanOf(const SampleHalves& h) {
  FloatImage m = h.a;
  for (size_t i = 0; i < m.rgba.size(); ++i) m.rgba[i] = 0.5f * (h.a.rgba[i] + h.b.rgba[i]);
  return m;
}

double meanSquaredError(const FloatImage& image, float (*truth)(uint32_t)) {
  double sum = 0;
  for (uint32_t y = 0; y < kSize; ++y)
    for (uint32_t x = 0; x < kSize; ++x) {
      const double d = image.at(x, y)[0] - truth(x);
      sum += d * d;
    }
  return sum / (kSize * kSize);
}

TEST(RuntimeDenoiseNlm, RemovesNoise) {
  FloatImage normal_depth, albedo;
  planeGuides(normal_depth, albedo, false);
  const SampleHalves h = noisyHalves(0.2f, 8, flatTruth, 21);
  const double before = meanSquaredError(meanOf(h), flatTruth);
  const double after = meanSquaredError(nlmDenoise(h, normal_depth, albedo), flatTruth);
  std::printf("nlm flat plane MSE %.3g -> %.3g (%.1fx)\n", before, after, before / after);
  EXPECT_GT(before / after, 10.0);
}

TEST(RuntimeDenoiseNlm, ZeroVarianceIsTheIdentity) {
  // Identical halves: the variance estimate is zero everywhere, so no neighbour
  // of a different value is accepted, however many features agree.
  FloatImage normal_depth, albedo;
  planeGuides(normal_depth, albedo, false, 4);
  SampleHalves h = noisyHalves(0.2f, 8, stepTruth, 22);
  h.b = h.a;
  const FloatImage out = nlmDenoise(h, normal_depth, albedo);
  for (size_t i = 0; i < out.pixelCount(); ++i)
    for (int c = 0; c < 3; ++c) ASSERT_FLOAT_EQ(out.rgba[i * 4 + c], h.a.rgba[i * 4 + c]) << i;
}

TEST(RuntimeDenoiseNlm, ErrorFallsAsSamplesRise) {
  // A shadow edge on one plane (no feature marks it). Per-sample noise 0.5: as
  // the sample count grows the denoised error falls, below the undenoised one,
  // and to nothing: the filter's strength falls with the variance.
  FloatImage normal_depth, albedo;
  planeGuides(normal_depth, albedo, false);
  double previous = 1e30;
  for (uint32_t samples : {2u, 8u, 32u, 128u, 512u, 1u << 14, 1u << 20}) {
    const SampleHalves h = noisyHalves(0.5f, samples, stepTruth, 23);
    const double raw = meanSquaredError(meanOf(h), stepTruth);
    const double error = meanSquaredError(nlmDenoise(h, normal_depth, albedo), stepTruth);
    std::printf("nlm on a shadow edge, %7u spp: MSE %.3g (undenoised %.3g)\n", 2 * samples, error, raw);
    EXPECT_LT(error, previous);
    EXPECT_LT(error, raw);
    previous = error;
  }
  EXPECT_LT(previous, 1e-8);  // the undenoised image has 1.2e-7 here
}

// nlr (nlm's weights with a first-order regression on the features) and its
// one-pass animation form nlr-fast: the same convergence guarantees.
TEST(RuntimeDenoiseNlr, ZeroVarianceIsTheIdentity) {
  FloatImage normal_depth, albedo;
  planeGuides(normal_depth, albedo, true, 4);
  SampleHalves h = noisyHalves(0.2f, 8, stepTruth, 25);
  h.b = h.a;
  for (const NlmParams& params : {nlrParams(), nlrFastParams()}) {
    const FloatImage out = nlmDenoise(h, normal_depth, albedo, params);
    for (size_t i = 0; i < out.pixelCount(); ++i)
      for (int c = 0; c < 3; ++c) ASSERT_FLOAT_EQ(out.rgba[i * 4 + c], h.a.rgba[i * 4 + c]) << i;
  }
}

TEST(RuntimeDenoiseNlr, ErrorFallsAsSamplesRise) {
  FloatImage normal_depth, albedo;
  planeGuides(normal_depth, albedo, false);
  for (const NlmParams& params : {nlrParams(), nlrFastParams()}) {
    const char* name = params.passes == 1 ? "nlr-fast" : "nlr";
    double previous = 1e30;
    for (uint32_t samples : {2u, 8u, 32u, 128u, 512u, 1u << 14, 1u << 20}) {
      const SampleHalves h = noisyHalves(0.5f, samples, stepTruth, 26);
      const double raw = meanSquaredError(meanOf(h), stepTruth);
      const double error = meanSquaredError(nlmDenoise(h, normal_depth, albedo, params), stepTruth);
      std::printf("%s on a shadow edge, %7u spp: MSE %.3g (undenoised %.3g)\n", name, 2 * samples, error, raw);
      EXPECT_LT(error, previous) << name;
      EXPECT_LT(error, raw) << name;
      previous = error;
    }
    EXPECT_LT(previous, 1e-8) << name;
  }
}

// nlr-fast is nlr with fewer offsets and passes: it removes less noise than nlr
// on a flat plane, but most of it.
TEST(RuntimeDenoiseNlr, FastFormRemovesMostNoise) {
  FloatImage normal_depth, albedo;
  planeGuides(normal_depth, albedo, false);
  const SampleHalves h = noisyHalves(0.2f, 8, flatTruth, 21);
  const double raw = meanSquaredError(meanOf(h), flatTruth);
  const double full = meanSquaredError(nlmDenoise(h, normal_depth, albedo, nlrParams()), flatTruth);
  const double fast = meanSquaredError(nlmDenoise(h, normal_depth, albedo, nlrFastParams()), flatTruth);
  std::printf("flat plane MSE: undenoised %.3g, nlr %.3g, nlr-fast %.3g\n", raw, full, fast);
  EXPECT_GT(raw / fast, 5.0);
  EXPECT_LT(full, fast);
}

float rampTruth(uint32_t x) { return 0.1f + 0.8f * float(x) / float(kSize - 1); }

TEST(RuntimeDenoiseNlr, RegressionFollowsAFeatureRamp) {
  // Colour proportional to an albedo ramp across the plane: the weighted mean
  // flattens the ramp (bias), the first-order fit on the albedo follows it.
  FloatImage normal_depth, albedo;
  planeGuides(normal_depth, albedo, false);
  for (uint32_t y = 0; y < kSize; ++y)
    for (uint32_t x = 0; x < kSize; ++x)
      for (int c = 0; c < 3; ++c) albedo.at(x, y)[c] = rampTruth(x);
  const SampleHalves h = noisyHalves(0.2f, 8, rampTruth, 27);
  NlmParams mean_only = nlrParams();
  mean_only.regression = false;
  const double raw = meanSquaredError(meanOf(h), rampTruth);
  const double mean_error = meanSquaredError(nlmDenoise(h, normal_depth, albedo, mean_only), rampTruth);
  const double fit_error = meanSquaredError(nlmDenoise(h, normal_depth, albedo, nlrParams()), rampTruth);
  std::printf("albedo ramp: MSE undenoised %.3g, weighted mean %.3g, regression %.3g\n", raw,
              mean_error, fit_error);
  EXPECT_LT(fit_error, 0.8 * mean_error);  // 0.64 when written
  EXPECT_LT(fit_error * 5.0, raw);
}

TEST(RuntimeDenoiseNlm, KeepsFeatureEdgesAndSky) {
  // Two planes meeting at a normal edge, four rows of sky (value 1) above: the
  // planes' means stay apart and the sky is never mixed with a surface.
  FloatImage normal_depth, albedo;
  planeGuides(normal_depth, albedo, true, 4);
  SampleHalves h = noisyHalves(0.2f, 8, stepTruth, 24);
  for (uint32_t y = 0; y < 4; ++y)
    for (uint32_t x = 0; x < kSize; ++x)
      for (int c = 0; c < 3; ++c) h.a.at(x, y)[c] = h.b.at(x, y)[c] = 1.0f;
  const FloatImage out = nlmDenoise(h, normal_depth, albedo);
  // Four columns each side of the edge (one column's mean keeps much of its own noise).
  double left = 0, right = 0;
  for (uint32_t y = 4; y < kSize; ++y)
    for (uint32_t i = 0; i < 4; ++i) {
      left += out.at(kSize / 2 - 1 - i, y)[0];
      right += out.at(kSize / 2 + i, y)[0];
    }
  EXPECT_NEAR(left / (4 * (kSize - 4)), 0.2, 0.01);
  EXPECT_NEAR(right / (4 * (kSize - 4)), 0.3, 0.01);
  for (uint32_t x = 0; x < kSize; ++x) EXPECT_FLOAT_EQ(out.at(x, 0)[1], 1.0f);
}

// The kernel's instruction sets (denoise_nlm_kernel.inc: the baseline, AVX2,
// AVX-512 where the CPU has them; SDFC_SIMD picks a lower one) give the same
// image up to float rounding (fused multiply-adds), on a noisy image with sky,
// a normal edge and an albedo ramp, nlm and nlr.
TEST(RuntimeDenoiseNlr, InstructionSetsAgree) {
  FloatImage normal_depth, albedo;
  planeGuides(normal_depth, albedo, true, 5);
  for (uint32_t y = 0; y < kSize; ++y)
    for (uint32_t x = 0; x < kSize; ++x)
      for (int c = 0; c < 3; ++c) albedo.at(x, y)[c] = rampTruth(x) * (c == 1 ? 0.5f : 1.0f);
  const SampleHalves h = noisyHalves(0.3f, 4, rampTruth, 28);
  for (const NlmParams& params : {NlmParams(), nlrParams(), nlrFastParams()}) {
    std::vector<FloatImage> images;
    for (const char* level : {"baseline", "avx2", "best"}) {
      setenv("SDFC_SIMD", level, 1);
      images.push_back(nlmDenoise(h, normal_depth, albedo, params));
    }
    unsetenv("SDFC_SIMD");
    for (size_t k = 1; k < images.size(); ++k) {
      double worst = 0;
      for (size_t i = 0; i < images[0].rgba.size(); ++i)
        worst = std::max<double>(worst, std::fabs(images[k].rgba[i] - images[0].rgba[i]) /
                                            std::max(1e-3f, std::fabs(images[0].rgba[i])));
      std::printf("%s: instruction set %zu against the baseline: largest relative difference %.3g\n",
                  params.regression ? "nlr" : "nlm", k, worst);
      EXPECT_LT(worst, 1e-4);
    }
  }
}

// Ctrl-C: a set interrupt stops the filter between blocks; the result is empty
// and `filtered` untouched.
TEST(RuntimeDenoiseNlr, InterruptStops) {
  FloatImage normal_depth, albedo;
  planeGuides(normal_depth, albedo, false);
  const SampleHalves h = noisyHalves(0.2f, 8, flatTruth, 29);
  std::atomic<bool> interrupt{true};
  NlmParams params = nlrParams();
  params.interrupt = &interrupt;
  SampleHalves filtered;
  EXPECT_TRUE(nlmDenoise(h, normal_depth, albedo, params, &filtered).empty());
  EXPECT_TRUE(filtered.a.empty());
  // Unset: a whole image, and progress reported up to 1.
  interrupt = false;
  double last = 0;
  int calls = 0;
  params.progress = [&](double share) {
    EXPECT_GE(share, last);
    last = share;
    ++calls;
  };
  EXPECT_FALSE(nlmDenoise(h, normal_depth, albedo, params).empty());
  EXPECT_GT(calls, 0);
  EXPECT_NEAR(last, 1.0, 1e-9);
}

TEST(RuntimeDenoiseNlm, DispatchNeedsHalves) {
  FloatImage normal_depth, albedo;
  planeGuides(normal_depth, albedo, false);
  SampleHalves halves;
  halves.a = FloatImage(kSize, kSize, 0.2f);
  halves.b = FloatImage(kSize, kSize, 0.3f);
  halves.samples_a = 2;
  halves.samples_b = 6;
  EXPECT_EQ(parseDenoiser("nlm"), Denoiser::Nlm);
  EXPECT_EQ(parseDenoiser("nlr"), Denoiser::Nlr);
  EXPECT_STREQ(denoiserName(Denoiser::Nlr), "nlr");
  EXPECT_TRUE(needsVariance(Denoiser::Nlr));
  EXPECT_TRUE(wantsJitteredAovs(Denoiser::Nlr));
  EXPECT_EQ(parseDenoiser("nlr-fast"), Denoiser::NlrFast);
  EXPECT_STREQ(denoiserName(Denoiser::NlrFast), "nlr-fast");
  EXPECT_TRUE(needsVariance(Denoiser::NlrFast));
  EXPECT_TRUE(wantsJitteredAovs(Denoiser::NlrFast));
  EXPECT_TRUE(wantsSpecularAovs(Denoiser::NlrFast));
  EXPECT_FALSE(wantsJitteredAovs(Denoiser::Nlm));
  EXPECT_STREQ(denoiserName(Denoiser::Nlm), "nlm");
  EXPECT_TRUE(needsVariance(Denoiser::Nlm));
  EXPECT_THROW(denoise(Denoiser::Nlm, halves.a, normal_depth, albedo), std::invalid_argument);
  halves.b.width = kSize / 2;
  EXPECT_THROW(nlmDenoise(halves, normal_depth, albedo), std::invalid_argument);
  halves.b.width = kSize;
  // Constant halves: the mean (0.2 * 2 + 0.3 * 6) / 8 = 0.275 comes out unchanged.
  const FloatImage out = denoise(Denoiser::Nlm, halves.a, normal_depth, albedo, &halves);
  for (size_t i = 0; i < out.pixelCount(); ++i)
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(out.rgba[i * 4 + c], 0.275f, 1e-6f);
}

}  // namespace
}  // namespace sdfc
