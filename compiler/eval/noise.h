// Gradient noise, the float64 twin of emit/kernel/noise.glsl: one definition
// for every feature that needs noise (colour fields now, `displace` later).
//
// Definition (Perlin's improved noise, with a different hash): the lattice
// corner c = floor(p) (integers) gets the gradient g = G[h(c) mod 12], G being
// the 12 cube-edge directions (±1, ±1, 0), (±1, 0, ±1), (0, ±1, ±1), and
// h(x, y, z) = H(x ^ H(y ^ H(z))) on 32-bit two's complement words, where H is
// the "lowbias32" integer mix: h ^= h >> 16; h *= 0x7feb352d; h ^= h >> 15;
// h *= 0x846ca68b; h ^= h >> 16. The noise is the trilinear blend of
// dot(g, p - c) over the 8 corners with weights from the quintic fade
// 6t^5 - 15t^4 + 10t^3 (Perlin 2002, "Improving noise", SIGGRAPH). It is 0 at
// every lattice point, continuous with a continuous gradient, and lies in
// about [-1, 1] (users clamp). The fractal sum of n octaves is
// sum_{i<n} 0.5^i noise(2^i p) / sum_{i<n} 0.5^i.
#pragma once
#include <cstdint>
#include <glm/glm.hpp>

namespace sdfc {

// Bounds on the noise and its gradient, for displace (passes/analyze.cpp).
// Write n = sum_k w_k c_k, c_k = g_k . (f - o_k), w_k the fade weights. Along
// x (t = f.x, u = fade(t)), at each (y, z) corner the two x corners give
// g_0x (1 - u - u' t) + g_1x (u - u' (1 - t)) + u' (a_1 - a_0), a_o the y, z
// part of c_o. A cube-edge gradient with g_x != 0 has one of g_y, g_z, and
// with g_x = 0 both, so corner o adds at most
// max(|alpha_o| + u' max(dy, dz), u' (dy + dz)), dy = |f.y - o.y|; summed with
// the (y, z) weights this bounds |dn/dx| by B_x(f), and |grad n| by
// |(B_x, B_y, B_z)|. Its maximum over a 401^3 grid of the cell is 6.4952, at
// the centre (3.75 sqrt(3)); sampled gradients reach 3.20
// (tests/deform_test.cpp recomputes both). Likewise |n| <= sum_k w_k (the
// two largest |f - o_k| components), at most 1.0364 on the grid.
constexpr double kNoiseGradientBound = 6.5;
constexpr double kNoiseRangeBound = 1.05;

uint32_t noiseHash(int32_t x, int32_t y, int32_t z);
double gradientNoise(const glm::dvec3& p);
double fractalNoise(const glm::dvec3& p, int octaves);

}  // namespace sdfc
