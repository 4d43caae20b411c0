// CPU denoisers: they keep what must be kept (constants, colour and normal
// edges) and remove measured amounts of noise.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "denoise.h"

namespace sdfc {
namespace {

constexpr uint32_t kSize = 64;

// Variance of channel 0 over the pixels with x in [x0, x1).
double channelVariance(const FloatImage& image, uint32_t x0, uint32_t x1) {
  double sum = 0, sum2 = 0, n = 0;
  for (uint32_t y = 0; y < image.height; ++y)
    for (uint32_t x = x0; x < x1; ++x) {
      const double v = image.at(x, y)[0];
      sum += v;
      sum2 += v * v;
      n += 1;
    }
  const double mean = sum / n;
  return sum2 / n - mean * mean;
}

FloatImage noisyFlat(float level, float sigma, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, sigma);
  FloatImage image(kSize, kSize, 1.0f);
  for (size_t i = 0; i < image.pixelCount(); ++i)
    for (int c = 0; c < 3; ++c) image.rgba[i * 4 + c] = level + noise(rng);
  return image;
}

// Guides for a scene split at x = kSize/2 into two planes facing +x and +y,
// both at depth 4 with a grey albedo; `miss_right` makes the right half sky.
void splitGuides(FloatImage& normal_depth, FloatImage& albedo, bool miss_right = false) {
  normal_depth = FloatImage(kSize, kSize);
  albedo = FloatImage(kSize, kSize, 0.5f);
  for (uint32_t y = 0; y < kSize; ++y)
    for (uint32_t x = 0; x < kSize; ++x) {
      float* n = normal_depth.at(x, y);
      const bool right = x >= kSize / 2;
      n[0] = right ? 0.0f : 1.0f;
      n[1] = right ? 1.0f : 0.0f;
      n[3] = (right && miss_right) ? -1.0f : 4.0f;
    }
}

TEST(RuntimeDenoise, ParsesNames) {
  EXPECT_EQ(parseDenoiser("bilateral"), Denoiser::Bilateral);
  EXPECT_EQ(parseDenoiser("atrous"), Denoiser::ATrous);
  EXPECT_EQ(parseDenoiser("none"), Denoiser::None);
  EXPECT_FALSE(parseDenoiser("oidn").has_value());
  for (Denoiser d : {Denoiser::None, Denoiser::Bilateral, Denoiser::ATrous})
    EXPECT_EQ(parseDenoiser(denoiserName(d)), d);
}

TEST(RuntimeDenoise, BilateralKeepsConstantsAndSteps) {
  FloatImage constant(kSize, kSize, 0.37f);
  const FloatImage filtered = bilateralFilter(constant);
  for (size_t i = 0; i < filtered.rgba.size(); ++i) ASSERT_NEAR(filtered.rgba[i], 0.37f, 1e-6f);

  FloatImage step(kSize, kSize, 1.0f);
  for (uint32_t y = 0; y < kSize; ++y)
    for (uint32_t x = 0; x < kSize; ++x)
      for (int c = 0; c < 3; ++c) step.at(x, y)[c] = x < kSize / 2 ? 0.2f : 0.8f;
  const FloatImage edge = bilateralFilter(step);
  for (uint32_t y = 0; y < kSize; ++y) {
    ASSERT_NEAR(edge.at(kSize / 2 - 1, y)[0], 0.2f, 1e-6f);  // range weight ~ e^-150
    ASSERT_NEAR(edge.at(kSize / 2, y)[0], 0.8f, 1e-6f);
  }
}

TEST(RuntimeDenoise, BilateralReducesNoise) {
  const FloatImage noisy = noisyFlat(0.5f, 0.02f, 1);
  const FloatImage filtered = bilateralFilter(noisy);
  const double factor = channelVariance(noisy, 2, kSize - 2) / channelVariance(filtered, 2, kSize - 2);
  RecordProperty("variance_reduction", std::to_string(factor));
  std::printf("bilateral variance reduction (sigma 0.02): %.1fx\n", factor);
  EXPECT_GT(factor, 8.0);  // 25 nearly equal weights would give 25x minus correlation
}

TEST(RuntimeDenoise, ATrousKeepsConstantsAndNormalEdges) {
  FloatImage normal_depth, albedo;
  splitGuides(normal_depth, albedo);
  FloatImage constant(kSize, kSize, 0.3f);
  const FloatImage flat = atrousFilter(constant, normal_depth, albedo);
  for (size_t i = 0; i < flat.rgba.size(); ++i) ASSERT_NEAR(flat.rgba[i], 0.3f, 1e-5f);

  // Noisy halves with different brightness, separated only by the normal edge:
  // the colour difference alone (0.1) is well inside the noise.
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(0.0f, 0.05f);
  FloatImage noisy(kSize, kSize, 1.0f);
  for (uint32_t y = 0; y < kSize; ++y)
    for (uint32_t x = 0; x < kSize; ++x)
      for (int c = 0; c < 3; ++c)
        noisy.at(x, y)[c] = (x < kSize / 2 ? 0.25f : 0.35f) + noise(rng);
  const FloatImage filtered = atrousFilter(noisy, normal_depth, albedo);
  double left_edge = 0, right_edge = 0;
  for (uint32_t y = 0; y < kSize; ++y) {
    left_edge += filtered.at(kSize / 2 - 1, y)[0];
    right_edge += filtered.at(kSize / 2, y)[0];
  }
  left_edge /= kSize;
  right_edge /= kSize;
  EXPECT_NEAR(left_edge, 0.25, 0.01);
  EXPECT_NEAR(right_edge, 0.35, 0.01);
  const double factor = channelVariance(noisy, 0, kSize / 2) / channelVariance(filtered, 0, kSize / 2);
  std::printf("a-trous variance reduction (sigma 0.05): %.1fx\n", factor);
  EXPECT_GT(factor, 10.0);

  // Without the normal guide the same edge would blur: check the guide matters.
  FloatImage flat_normals = normal_depth;
  for (uint32_t y = 0; y < kSize; ++y)
    for (uint32_t x = 0; x < kSize; ++x) {
      flat_normals.at(x, y)[0] = 1;
      flat_normals.at(x, y)[1] = 0;
    }
  const FloatImage blurred = atrousFilter(noisy, flat_normals, albedo);
  double blurred_left = 0;
  for (uint32_t y = 0; y < kSize; ++y) blurred_left += blurred.at(kSize / 2 - 1, y)[0];
  blurred_left /= kSize;
  std::printf("edge column mean: with normals %.4f, without %.4f (truth 0.25)\n", left_edge,
              blurred_left);
  EXPECT_LT(std::fabs(left_edge - 0.25), 0.5 * std::fabs(blurred_left - 0.25));
}

TEST(RuntimeDenoise, ATrousNeverMixesSkyAndSurface) {
  FloatImage normal_depth, albedo;
  splitGuides(normal_depth, albedo, /*miss_right=*/true);
  FloatImage image(kSize, kSize, 1.0f);
  for (uint32_t y = 0; y < kSize; ++y)
    for (uint32_t x = 0; x < kSize; ++x)
      for (int c = 0; c < 3; ++c) image.at(x, y)[c] = x < kSize / 2 ? 0.1f : 0.3f;
  const FloatImage filtered = atrousFilter(image, normal_depth, albedo);
  for (uint32_t y = 0; y < kSize; ++y) {
    ASSERT_NEAR(filtered.at(kSize / 2 - 1, y)[0], 0.1f, 1e-5f);
    ASSERT_NEAR(filtered.at(kSize / 2, y)[0], 0.3f, 1e-5f);
  }
}

TEST(RuntimeDenoise, ATrousKeepsAlbedoTexture) {
  // A checkerboard albedo under smooth lighting: demodulation keeps it sharp.
  FloatImage normal_depth(kSize, kSize), albedo(kSize, kSize, 1.0f), color(kSize, kSize, 1.0f);
  for (uint32_t y = 0; y < kSize; ++y)
    for (uint32_t x = 0; x < kSize; ++x) {
      normal_depth.at(x, y)[2] = 1;
      normal_depth.at(x, y)[3] = 3;
      const float a = ((x / 4 + y / 4) % 2) ? 0.8f : 0.2f;
      for (int c = 0; c < 3; ++c) {
        albedo.at(x, y)[c] = a;
        color.at(x, y)[c] = a * 0.7f;  // irradiance 0.7 everywhere
      }
    }
  const FloatImage filtered = atrousFilter(color, normal_depth, albedo);
  for (size_t i = 0; i < color.rgba.size(); ++i) ASSERT_NEAR(filtered.rgba[i], color.rgba[i], 1e-5f);
}

TEST(RuntimeDenoise, DispatchNoneIsIdentity) {
  const FloatImage noisy = noisyFlat(0.5f, 0.1f, 3);
  FloatImage normal_depth(kSize, kSize), albedo(kSize, kSize, 1.0f);
  EXPECT_EQ(denoise(Denoiser::None, noisy, normal_depth, albedo).rgba, noisy.rgba);
  EXPECT_NE(denoise(Denoiser::Bilateral, noisy, normal_depth, albedo).rgba, noisy.rgba);
}

}  // namespace
}  // namespace sdfc
