// The variance-guided denoiser: its variance estimate is the sample-count
// weighted formula, it removes noise it is told about, keeps normal edges, and
// its strength falls to nothing as the variance does (no bias at convergence).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "denoise.h"
#include "denoise_svgf.h"

namespace sdfc {
namespace {

constexpr uint32_t kSize = 64;

// One plane facing the camera at depth 5 (left half normal +z, right half +x
// when `split_normals`), grey albedo.
void planeGuides(FloatImage& normal_depth, FloatImage& albedo, bool split_normals) {
  normal_depth = FloatImage(kSize, kSize);
  albedo = FloatImage(kSize, kSize, 0.5f);
  for (uint32_t y = 0; y < kSize; ++y)
    for (uint32_t x = 0; x < kSize; ++x) {
      float* n = normal_depth.at(x, y);
      const bool right = split_normals && x >= kSize / 2;
      n[0] = right ? 1.0f : 0.0f;
      n[2] = right ? 0.0f : 1.0f;
      n[3] = 5.0f;
    }
}

// Two independent half renders of `truth(x)` with per-sample noise sigma and
// `samples` samples each; returns their mean, and the variance estimate.
void noisyHalves(float sigma, uint32_t samples, float (*truth)(uint32_t), uint32_t seed,
                 FloatImage& mean, FloatImage& variance) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, sigma / std::sqrt(float(samples)));
  FloatImage a(kSize, kSize, 1.0f), b(kSize, kSize, 1.0f);
  mean = FloatImage(kSize, kSize, 1.0f);
  for (uint32_t y = 0; y < kSize; ++y)
    for (uint32_t x = 0; x < kSize; ++x) {
      const float n_a = noise(rng), n_b = noise(rng);  // grey noise: one path, three channels
      for (int c = 0; c < 3; ++c) {
        a.at(x, y)[c] = truth(x) + n_a;
        b.at(x, y)[c] = truth(x) + n_b;
        mean.at(x, y)[c] = 0.5f * (a.at(x, y)[c] + b.at(x, y)[c]);
      }
    }
  variance = varianceFromHalves(a, samples, b, samples);
}

float stepTruth(uint32_t x) { return x < kSize / 2 ? 0.2f : 0.3f; }
float flatTruth(uint32_t) { return 0.25f; }

double meanSquaredError(const FloatImage& image, float (*truth)(uint32_t), uint32_t x0, uint32_t x1) {
  double sum = 0, n = 0;
  for (uint32_t y = 0; y < kSize; ++y)
    for (uint32_t x = x0; x < x1; ++x) {
      const double d = image.at(x, y)[0] - truth(x);
      sum += d * d;
      n += 1;
    }
  return sum / n;
}

TEST(RuntimeDenoiseSvgf, VarianceFromHalvesWeighsSampleCounts) {
  FloatImage a(1, 1, 0.0f), b(1, 1, 0.0f);
  a.rgba = {1.0f, 2.0f, 0.0f, 1.0f};
  b.rgba = {0.0f, 2.0f, 3.0f, 1.0f};
  // Var(mean) = (a - b)^2 n_a n_b / (n_a + n_b)^2: here 1 * 3 / 16 per unit^2.
  const FloatImage v = varianceFromHalves(a, 1, b, 3);
  EXPECT_FLOAT_EQ(v.rgba[0], 3.0f / 16);
  EXPECT_FLOAT_EQ(v.rgba[1], 0.0f);
  EXPECT_FLOAT_EQ(v.rgba[2], 9.0f * 3 / 16);
  const float d_lum = 0.2126f * 1 - 0.0722f * 3;
  EXPECT_NEAR(v.rgba[3], d_lum * d_lum * 3 / 16, 1e-6f);
}

TEST(RuntimeDenoiseSvgf, RemovesTheNoiseItIsToldAbout) {
  FloatImage normal_depth, albedo, mean, variance;
  planeGuides(normal_depth, albedo, false);
  noisyHalves(0.2f, 8, flatTruth, 11, mean, variance);
  const FloatImage filtered = svgfFilter(mean, variance, normal_depth, albedo);
  const double before = meanSquaredError(mean, flatTruth, 0, kSize);
  const double after = meanSquaredError(filtered, flatTruth, 0, kSize);
  std::printf("svgf flat plane MSE %.3g -> %.3g (%.1fx)\n", before, after, before / after);
  EXPECT_GT(before / after, 20.0);
}

TEST(RuntimeDenoiseSvgf, KeepsNormalEdges) {
  FloatImage normal_depth, albedo, mean, variance;
  planeGuides(normal_depth, albedo, true);
  noisyHalves(0.2f, 8, stepTruth, 12, mean, variance);
  const FloatImage filtered = svgfFilter(mean, variance, normal_depth, albedo);
  double left = 0, right = 0;
  for (uint32_t y = 0; y < kSize; ++y) {
    left += filtered.at(kSize / 2 - 1, y)[0];
    right += filtered.at(kSize / 2, y)[0];
  }
  EXPECT_NEAR(left / kSize, 0.2, 0.01);
  EXPECT_NEAR(right / kSize, 0.3, 0.01);
}

TEST(RuntimeDenoiseSvgf, StrengthFallsWithVariance) {
  // A shadow edge on one plane (no feature marks it): with much noise the filter
  // blurs across it, as the noise hides it; as the variance falls to zero the
  // edge comes back exactly: the filter converges to the unfiltered image.
  FloatImage normal_depth, albedo;
  planeGuides(normal_depth, albedo, false);
  FloatImage exact(kSize, kSize, 1.0f);
  for (uint32_t y = 0; y < kSize; ++y)
    for (uint32_t x = 0; x < kSize; ++x)
      for (int c = 0; c < 3; ++c) exact.at(x, y)[c] = stepTruth(x);
  double previous = 1e30;
  for (float sigma : {0.3f, 0.03f, 0.003f, 0.0f}) {
    FloatImage variance(kSize, kSize, sigma * sigma);
    const FloatImage filtered = svgfFilter(exact, variance, normal_depth, albedo);
    const double error = meanSquaredError(filtered, stepTruth, 0, kSize);
    std::printf("svgf on an exact edge, noise sigma %.3f: MSE %.3g\n", sigma, error);
    EXPECT_LE(error, previous);
    previous = error;
  }
  EXPECT_LT(previous, 1e-10);
}

TEST(RuntimeDenoiseSvgf, DispatchNeedsHalves) {
  FloatImage normal_depth, albedo;
  planeGuides(normal_depth, albedo, false);
  SampleHalves halves;
  halves.a = FloatImage(kSize, kSize, 0.2f);
  halves.b = FloatImage(kSize, kSize, 0.3f);
  halves.samples_a = 2;
  halves.samples_b = 6;
  EXPECT_EQ(parseDenoiser("svgf"), Denoiser::Svgf);
  EXPECT_TRUE(needsVariance(Denoiser::Svgf));
  EXPECT_FALSE(needsVariance(Denoiser::ATrous));
  EXPECT_THROW(denoise(Denoiser::Svgf, halves.a, normal_depth, albedo), std::invalid_argument);
  // Constant halves: the mean (0.2 * 2 + 0.3 * 6) / 8 = 0.275 comes out unchanged.
  const FloatImage out = denoise(Denoiser::Svgf, halves.a, normal_depth, albedo, &halves);
  for (size_t i = 0; i < out.pixelCount(); ++i)
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(out.rgba[i * 4 + c], 0.275f, 1e-6f);
}

}  // namespace
}  // namespace sdfc
