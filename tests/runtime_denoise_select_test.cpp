// Per-pixel selection among candidate filterings (denoise_select.h, nlm/nlr's
// select_k): it picks, region by region, the candidate that is right there,
// and keeps nlr's guarantees: identity at zero variance, error falling to zero
// as the samples rise.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "denoise_nlm.h"
#include "denoise_select.h"

namespace sdfc {
namespace {

constexpr int kSize = 48;

float stepTruth(int x) { return x < kSize / 2 ? 0.2f : 0.3f; }

// Halves of truth(x) plus independent Gaussian noise of deviation sigma; grey.
void noisyPlanes(float sigma, uint32_t seed, std::vector<float>& a, std::vector<float>& b) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, sigma);
  a.resize(size_t(kSize) * kSize * 3);
  b.resize(a.size());
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const float n_a = noise(rng), n_b = noise(rng);
      for (int c = 0; c < 3; ++c) {
        a[(size_t(y) * kSize + x) * 3 + c] = stepTruth(x) + n_a;
        b[(size_t(y) * kSize + x) * 3 + c] = stepTruth(x) + n_b;
      }
    }
}

// The truth, off by `offset` on the left half (left) or the right half.
std::vector<float> biasedTruth(bool left, float offset) {
  std::vector<float> out(size_t(kSize) * kSize * 3);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x)
      for (int c = 0; c < 3; ++c)
        out[(size_t(y) * kSize + x) * 3 + c] = stepTruth(x) + ((x < kSize / 2) == left ? offset : 0.0f);
  return out;
}

double meanSquaredError(const std::vector<float>& image) {
  double sum = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const double d = image[(size_t(y) * kSize + x) * 3] - stepTruth(x);
      sum += d * d;
    }
  return sum / (kSize * kSize);
}

TEST(RuntimeDenoiseSelect, PicksTheCandidateRightInEachRegion) {
  // Candidate 0 is wrong by 0.1 on the left, candidate 1 on the right; the
  // halves are noisier (0.1) than either error is visible in one pixel.
  std::vector<float> a, b;
  noisyPlanes(0.1f, 31, a, b);
  const std::vector<std::vector<float>> candidates = {biasedTruth(true, 0.1f), biasedTruth(false, 0.1f)};
  std::vector<float> out_a, out_b;
  std::vector<int> choice;
  selectPerPixel(candidates, candidates, a, b, kSize, kSize, SelectParams(), out_a, out_b, &choice);
  int wrong = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x)
      if (std::abs(x - kSize / 2) > 3)  // the box straddles the boundary within 2 pixels
        wrong += choice[size_t(y) * kSize + x] != (x < kSize / 2 ? 1 : 0);
  std::printf("select: %d of %d pixels away from the boundary chose wrong; MSE %.3g (candidates %.3g)\n",
              wrong, kSize * (kSize - 7), meanSquaredError(out_a), meanSquaredError(candidates[0]));
  EXPECT_LT(wrong, kSize * (kSize - 7) / 50);
  EXPECT_LT(meanSquaredError(out_a), 0.1 * meanSquaredError(candidates[0]));
  EXPECT_LT(meanSquaredError(out_b), 0.1 * meanSquaredError(candidates[1]));
}

TEST(RuntimeDenoiseSelect, NeedsMatchingCandidates) {
  std::vector<float> a, b, out_a, out_b;
  noisyPlanes(0.1f, 32, a, b);
  EXPECT_THROW(selectPerPixel({}, {}, a, b, kSize, kSize, SelectParams(), out_a, out_b),
               std::invalid_argument);
  EXPECT_THROW(selectPerPixel({a}, {a, b}, a, b, kSize, kSize, SelectParams(), out_a, out_b),
               std::invalid_argument);
}

// nlr with three last-pass strengths: its features and halves as an image.
struct Scene {
  FloatImage normal_depth{kSize, kSize}, albedo{kSize, kSize, 0.5f};
  SampleHalves halves;
  Scene(float sigma, uint32_t samples, uint32_t seed) {
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) {
        normal_depth.at(x, y)[2] = 1.0f;
        normal_depth.at(x, y)[3] = 5.0f;
      }
    std::vector<float> a, b;
    noisyPlanes(sigma / std::sqrt(float(samples)), seed, a, b);
    halves.a = FloatImage(kSize, kSize, 1.0f);
    halves.b = FloatImage(kSize, kSize, 1.0f);
    halves.samples_a = halves.samples_b = samples;
    for (size_t i = 0; i < size_t(kSize) * kSize; ++i)
      for (int c = 0; c < 3; ++c) {
        halves.a.rgba[i * 4 + c] = a[i * 3 + c];
        halves.b.rgba[i * 4 + c] = b[i * 3 + c];
      }
  }
};

NlmParams selecting() {
  NlmParams params = nlrParams();
  params.select_k = {0.7f, 1.25f, 2.5f};
  return params;
}

double imageError(const FloatImage& image) {
  double sum = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const double d = image.at(x, y)[0] - stepTruth(x);
      sum += d * d;
    }
  return sum / (kSize * kSize);
}

TEST(RuntimeDenoiseSelect, ZeroVarianceIsTheIdentity) {
  Scene scene(0.2f, 8, 33);
  scene.halves.b = scene.halves.a;
  const FloatImage out = nlmDenoise(scene.halves, scene.normal_depth, scene.albedo, selecting());
  for (size_t i = 0; i < out.pixelCount(); ++i)
    for (int c = 0; c < 3; ++c) ASSERT_FLOAT_EQ(out.rgba[i * 4 + c], scene.halves.a.rgba[i * 4 + c]) << i;
}

TEST(RuntimeDenoiseSelect, ErrorFallsAsSamplesRise) {
  // A shadow edge no feature marks, per-sample noise 0.5, as in the nlr tests.
  double previous = 1e30;
  for (uint32_t samples : {2u, 8u, 32u, 128u, 512u, 1u << 14, 1u << 20}) {
    const Scene scene(0.5f, samples, 34);
    FloatImage raw(kSize, kSize);
    for (size_t i = 0; i < raw.rgba.size(); ++i)
      raw.rgba[i] = 0.5f * (scene.halves.a.rgba[i] + scene.halves.b.rgba[i]);
    const double error =
        imageError(nlmDenoise(scene.halves, scene.normal_depth, scene.albedo, selecting()));
    std::printf("nlr + select on a shadow edge, %7u spp: MSE %.3g (undenoised %.3g)\n", 2 * samples,
                error, imageError(raw));
    EXPECT_LT(error, previous);
    EXPECT_LT(error, imageError(raw));
    previous = error;
  }
  EXPECT_LT(previous, 1e-8);
}

}  // namespace
}  // namespace sdfc
