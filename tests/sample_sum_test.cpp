// sampleTerm converts a pass's mean * count to 128-bit fixed point by shifting
// the double's mantissa; it must equal the compiler's own conversion,
// static_cast<__int128>(term * 2^64) (truncation toward zero), bit for bit.
#include "runtime/sample_sum.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>

namespace sdfc {
namespace {

// The conversion sampleTerm replaced, with the same cap.
SampleSum castTerm(float mean, uint32_t count) {
  double term = double(mean) * double(count);
  if (!(std::fabs(term) < kSampleSumLimit)) term = std::isnan(term) ? 0.0 : std::copysign(kSampleSumLimit, term);
  return static_cast<SampleSum>(term * kSampleSumScale);
}

bool sameBits(SampleSum a, SampleSum b) { return a == b; }

TEST(SampleSum, ShiftConversionEqualsTheCastOnEdgeCases) {
  const float kInf = std::numeric_limits<float>::infinity();
  const float edge_means[] = {0.0f, -0.0f, 1.0f, -1.0f, 0.5f, 1e-30f, -1e-30f,
                              std::ldexp(1.0f, -64), std::ldexp(1.0f, -65), std::ldexp(1.5f, -64),
                              std::numeric_limits<float>::denorm_min(), std::numeric_limits<float>::min(),
                              std::numeric_limits<float>::max(), -std::numeric_limits<float>::max(), kInf, -kInf,
                              std::numeric_limits<float>::quiet_NaN(), 3.0e18f, 4.6e18f, 4.7e18f, 1.1754942e-38f};
  const uint32_t edge_counts[] = {0u, 1u, 2u, 3u, 255u, 65536u, 4294967295u};
  for (float mean : edge_means)
    for (uint32_t count : edge_counts)
      EXPECT_TRUE(sameBits(sampleTerm(mean, count), castTerm(mean, count))) << "mean " << mean << " count " << count;
}

TEST(SampleSum, ShiftConversionEqualsTheCastOnRandomTerms) {
  std::mt19937_64 rng(12345);
  int mismatches = 0;
  for (int i = 0; i < 2000000; ++i) {
    // Random bit patterns cover every exponent; random counts every magnitude of the product.
    uint32_t bits = uint32_t(rng());
    float mean;
    std::memcpy(&mean, &bits, sizeof mean);
    const uint32_t count = (i & 1) ? uint32_t(rng()) : uint32_t(rng() % 4096);
    if (!sameBits(sampleTerm(mean, count), castTerm(mean, count))) ++mismatches;
  }
  EXPECT_EQ(mismatches, 0);
}

TEST(SampleSum, SumsOfTermsRoundTripToTheMean) {
  // Split sums of the same terms agree bit for bit, and the mean of n equal terms is the term.
  const float v = 0.123456789f;
  SampleSum whole = sampleTerm(v, 96);
  SampleSum split = sampleTerm(v, 32) + sampleTerm(v, 64);
  EXPECT_TRUE(sameBits(whole, split));
  EXPECT_EQ(sampleMean(whole, 96), v);
}

// render()'s one-pass resolve and the viewer's first pass take onePassMean's
// shortcut; it must give the long way's bits for every float and count.
TEST(SampleSum, OnePassMeanIsTheLongWayBitForBit) {
  auto same = [](float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; };
  auto longWay = [](float v, uint32_t count) { return sampleMean(sampleTerm(v, count), count); };
  const float edges[] = {0.0f, -0.0f, 1.0f, -1.0f, 0x1p-41f, -0x1p-41f, 0x1.fffffep-42f, 1e-30f,
                         std::numeric_limits<float>::denorm_min(), std::numeric_limits<float>::max(),
                         std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN(),
                         0x1p33f, 0x1p32f, 4.6e18f};
  const uint32_t counts[] = {1u, 2u, 3u, 64u, 1u << 29, (1u << 29) + 1, 4294967295u};
  for (float v : edges)
    for (uint32_t count : counts)
      EXPECT_TRUE(same(onePassMean(v, count), longWay(v, count))) << "v " << v << " count " << count;
  std::mt19937_64 rng(777);
  int mismatches = 0;
  for (int i = 0; i < 1000000; ++i) {
    const uint32_t bits = uint32_t(rng());
    float v;
    std::memcpy(&v, &bits, sizeof v);
    const uint32_t count = (i & 1) ? 1u : uint32_t(rng() % 70000) + 1;
    if (!same(onePassMean(v, count), longWay(v, count))) ++mismatches;
  }
  EXPECT_EQ(mismatches, 0);
}

}  // namespace
}  // namespace sdfc
