// Fireflies must not become squares (issue 29): a caustic's rare bright samples
// made nlm and nlr draw bright 11 px squares, since the variance around a
// firefly is huge and every pixel near it then accepts its whole window. The
// halves are clamped against each other first (denoise_fireflies.h).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "denoise.h"
#include "denoise_fireflies.h"
#include "denoise_nlm.h"
#include "image_io.h"

namespace sdfc {
namespace {

constexpr uint32_t kSize = 60;   // 6 x 6 blocks of 10 x 10
constexpr float kTruth = 0.05f;  // a shadow on a table

// A flat grey plane, depth 4, facing the camera.
void flatGuides(FloatImage& normal_depth, FloatImage& albedo) {
  normal_depth = FloatImage(kSize, kSize);
  albedo = FloatImage(kSize, kSize, 0.5f);
  for (size_t i = 0; i < normal_depth.pixelCount(); ++i) {
    normal_depth.rgba[i * 4 + 2] = 1.0f;
    normal_depth.rgba[i * 4 + 3] = 4.0f;
  }
}

// Two halves of 8 samples of a dark shadow with Gaussian noise, and in each
// half a few isolated fireflies (one sample of 320, so a half's mean is 40),
// none at the same pixel in both halves.
SampleHalves shadowWithFireflies(uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, 0.02f);
  SampleHalves h;
  h.a = FloatImage(kSize, kSize, 1.0f);
  h.b = FloatImage(kSize, kSize, 1.0f);
  h.samples_a = h.samples_b = 8;
  for (size_t i = 0; i < h.a.pixelCount(); ++i) {
    const float na = noise(rng), nb = noise(rng);
    for (int c = 0; c < 3; ++c) {
      h.a.rgba[i * 4 + c] = std::max(0.0f, kTruth + na);
      h.b.rgba[i * 4 + c] = std::max(0.0f, kTruth + nb);
    }
  }
  const uint32_t spots_a[][2] = {{7, 8}, {33, 14}, {52, 41}, {18, 47}};
  const uint32_t spots_b[][2] = {{44, 6}, {25, 30}, {8, 55}};
  for (const auto& s : spots_a)
    for (int c = 0; c < 3; ++c) h.a.at(s[0], s[1])[c] = 40.0f;
  for (const auto& s : spots_b)
    for (int c = 0; c < 3; ++c) h.b.at(s[0], s[1])[c] = 40.0f;
  return h;
}

// Mean absolute difference of the displayed bytes (default tone curve, sRGB)
// from the truth's, per 10 x 10 block.
std::vector<double> blockDisplayErrors(const FloatImage& image) {
  const std::vector<uint8_t> bytes = toSrgb8(image, ToneMap{});
  FloatImage truth_image(1, 1, kTruth);
  const int truth = toSrgb8(truth_image, ToneMap{})[0];
  std::vector<double> out;
  for (uint32_t by = 0; by < kSize; by += 10)
    for (uint32_t bx = 0; bx < kSize; bx += 10) {
      double sum = 0;
      for (uint32_t y = by; y < by + 10; ++y)
        for (uint32_t x = bx; x < bx + 10; ++x)
          for (int c = 0; c < 3; ++c) sum += std::abs(int(bytes[(size_t(y) * kSize + x) * 3 + c]) - truth);
      out.push_back(sum / 300.0);
    }
  return out;
}

TEST(DenoiseFireflies, NoBlockWorseThanUndenoised) {
  FloatImage normal_depth, albedo;
  flatGuides(normal_depth, albedo);
  const SampleHalves halves = shadowWithFireflies(5);
  FloatImage mean = halves.a;
  for (size_t i = 0; i < mean.rgba.size(); ++i) mean.rgba[i] = 0.5f * (halves.a.rgba[i] + halves.b.rgba[i]);
  const std::vector<double> raw = blockDisplayErrors(mean);
  for (Denoiser d : {Denoiser::Nlr, Denoiser::Nlm}) {
    SCOPED_TRACE(denoiserName(d));
    const FloatImage out = denoise(d, mean, normal_depth, albedo, &halves);
    const std::vector<double> filtered = blockDisplayErrors(out);
    double worst = 0;
    for (size_t i = 0; i < raw.size(); ++i) {
      EXPECT_LE(filtered[i], raw[i] + 0.5) << "block " << i % 6 << "," << i / 6;
      worst = std::max(worst, filtered[i] - raw[i]);
    }
    std::printf("%s: worst block %.2f bytes worse than undenoised\n", denoiserName(d), worst);
  }
  // The filter as it was (no clamp) draws the squares: this test fails on it.
  NlmParams old = nlrParams();
  old.clamp_fireflies = false;
  const std::vector<double> squares = blockDisplayErrors(nlmDenoise(halves, normal_depth, albedo, old));
  double worst_old = 0;
  for (size_t i = 0; i < raw.size(); ++i) worst_old = std::max(worst_old, squares[i] - raw[i]);
  std::printf("nlr without the clamp: worst block %.2f bytes worse than undenoised\n", worst_old);
  EXPECT_GT(worst_old, 2.0);
}

TEST(DenoiseFireflies, ConvergedAndSharedDetailUntouched) {
  // Identical halves (convergence): nothing changes, a lone bright pixel included.
  SampleHalves same = shadowWithFireflies(6);
  same.b = same.a;
  const SampleHalves before = same;
  EXPECT_EQ(clampFireflies(same), 0u);
  EXPECT_EQ(same.a.rgba, before.a.rgba);
  EXPECT_EQ(same.b.rgba, before.b.rgba);

  // A firefly in one half only is brought to ratio x the larger of its 5x5
  // median and the other half's pixel, hue kept; the other half is untouched there.
  SampleHalves h = shadowWithFireflies(7);
  h.a.at(33, 14)[0] = 80.0f;  // reddish
  const float b_before = h.b.at(33, 14)[0];
  EXPECT_GT(clampFireflies(h), 0u);
  const float* p = h.a.at(33, 14);
  EXPECT_LT(p[0], 1.0f);
  EXPECT_NEAR(p[0] / p[1], 2.0f, 1e-4f);
  EXPECT_EQ(h.b.at(33, 14)[0], b_before);

  // Dense fireflies (glass: one pixel in 4 of each half) are clamped all the
  // same; a thin bright line both halves see is kept.
  SampleHalves dense = shadowWithFireflies(8);
  for (uint32_t y = 0; y < kSize; ++y)
    for (uint32_t x = 0; x < kSize; ++x) {
      for (int c = 0; c < 3; ++c) dense.a.at(x, y)[c] = dense.b.at(x, y)[c] = kTruth;
      FloatImage& half = (x + y) % 2 ? dense.a : dense.b;
      if ((x / 2 + y) % 2 == 0)
        for (int c = 0; c < 3; ++c) half.at(x, y)[c] = 30.0f;
      if (x == 20)
        for (int c = 0; c < 3; ++c) dense.a.at(x, y)[c] = dense.b.at(x, y)[c] = 5.0f;
    }
  clampFireflies(dense);
  float brightest = 0;
  for (uint32_t y = 0; y < kSize; ++y)
    for (uint32_t x = 0; x < kSize; ++x)
      if (x != 20) brightest = std::max({brightest, dense.a.at(x, y)[0], dense.b.at(x, y)[0]});
  EXPECT_LT(brightest, 1.0f);
  for (uint32_t y = 0; y < kSize; ++y) {
    EXPECT_EQ(dense.a.at(20, y)[0], 5.0f);
    EXPECT_EQ(dense.b.at(20, y)[0], 5.0f);
  }
}

}  // namespace
}  // namespace sdfc
