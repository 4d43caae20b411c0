// Three non-negative floats in one 32-bit word with a shared exponent, as
// GL_EXT_texture_shared_exponent's RGB9_E5 (9-bit mantissas, exponent bias
// 15; its encoding formulas), the bits arranged so that the word read as a
// float is never a NaN or infinity (the scene data are floats): r in bits
// 0-8, g in 9-17, b's low 5 bits in 18-22, the exponent in 23-27 (at most
// 30), b's high 4 bits in 28-31. kernel/envmap.glsl's sdEnvTexel decodes it.
// A channel is within half a step of the largest channel's 9 bits (at least
// 256 steps for a largest channel from 2^-15 up): error at most 2^-9 of the
// largest channel.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>

namespace sdfc {

// The largest value stored: 511 / 512 * 2^(30 - 15).
constexpr float kSharedExponentMax = 511.0f / 512.0f * 32768.0f;

inline uint32_t packSharedExponent(glm::vec3 c) {
  c = glm::clamp(c, 0.0f, kSharedExponentMax);
  const float top = std::max(c.x, std::max(c.y, c.z));
  if (!(top > 0.0f)) return 0;
  int e2;
  std::frexp(top, &e2);  // top = f 2^e2, f in [0.5, 1): floor(log2(top)) = e2 - 1
  int e = std::max(-16, e2 - 1) + 16;
  if (std::floor(std::ldexp(top, 24 - e) + 0.5f) >= 512.0f) ++e;
  auto q = [&](float v) { return uint32_t(std::min(511.0f, std::floor(std::ldexp(v, 24 - e) + 0.5f))); };
  const uint32_t b = q(c.z);
  return q(c.x) | (q(c.y) << 9) | ((b & 31u) << 18) | (uint32_t(e) << 23) | ((b >> 5) << 28);
}

inline glm::vec3 unpackSharedExponent(uint32_t w) {
  const uint32_t b = ((w >> 18) & 31u) | ((w >> 23) & 480u);
  return glm::vec3(float(w & 511u), float((w >> 9) & 511u), float(b)) * std::ldexp(1.0f, int((w >> 23) & 31u) - 24);
}

}  // namespace sdfc
