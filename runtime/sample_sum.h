// Exact, order-independent sums of sample radiance.
//
// A pass returns each pixel's mean over its samples as a float; the renderer adds
// mean * count per pass. In floating point that sum depends on the order of the
// additions, so a render split into shards (sample ranges summed separately, then
// added) would differ in the last bits from one process summing pass after pass.
// Instead each term is turned into a fixed-point integer with 64 fraction bits
// (exact for every float term of magnitude 2^-64 .. 2^62, which covers radiance
// times any sample count), and integers add associatively: any split of the pass
// sequence sums to the same bits. The mean is rounded to float once, at the end.
#pragma once
#include <cmath>
#include <cstdint>
#include <cstring>

namespace sdfc {

using SampleSum = __int128;

constexpr double kSampleSumScale = 18446744073709551616.0;  // 2^64: fraction bits
constexpr double kSampleSumLimit = 4611686018427387904.0;   // 2^62: |term| cap

// mean * count as fixed point. float * integer <= 2^32 is exact in double, and the
// power-of-two scale is exact too, so only bits below 2^-64 are dropped.
// Equal to static_cast<SampleSum>(term * 2^64) (truncation toward zero), but from
// the double's bits with inline shifts: the compiler's 128-bit conversion is a
// library call, several times slower per pixel.
inline SampleSum sampleTerm(float mean, uint32_t count) {
  double term = double(mean) * double(count);
  if (!(std::fabs(term) < kSampleSumLimit)) term = std::isnan(term) ? 0.0 : std::copysign(kSampleSumLimit, term);
  uint64_t bits;
  std::memcpy(&bits, &term, sizeof bits);
  const int biased = int((bits >> 52) & 0x7ff);
  if (biased == 0) return 0;  // zero or subnormal: below 2^-64
  const uint64_t mantissa = (bits & ((uint64_t(1) << 52) - 1)) | (uint64_t(1) << 52);
  // term = mantissa * 2^(biased - 1075); times 2^64.
  const int shift = biased - 1075 + 64;
  SampleSum magnitude;
  if (shift >= 0) magnitude = static_cast<SampleSum>(mantissa) << shift;  // shift <= 63 + 11 below the cap
  else magnitude = shift <= -64 ? 0 : static_cast<SampleSum>(mantissa >> -shift);
  return (bits >> 63) ? -magnitude : magnitude;
}

// The mean of `count` samples whose sum is `sum`, rounded to float.
inline float sampleMean(SampleSum sum, uint64_t count) {
  if (count == 0) return 0.0f;
  return static_cast<float>(static_cast<double>(sum) / kSampleSumScale / double(count));
}

// sampleMean(sampleTerm(v, count), count) without the fixed point where that is v
// itself: for 2^-41 <= |v| and |v| count < 2^62 (count <= 2^29), v count is exact
// in double and v count 2^64 an integer, so nothing is dropped and the division
// gives v back. Zeros (-0 becomes +0), tiny values, NaN and inf take the long way.
inline float onePassMean(float v, uint32_t count) {
  const float a = std::fabs(v);
  if (a >= 0x1p-41f && count <= (1u << 29) && double(a) * count < kSampleSumLimit) return v;
  return sampleMean(sampleTerm(v, count), count);
}

}  // namespace sdfc
