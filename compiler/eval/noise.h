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
#include <vector>
#include <glm/glm.hpp>

namespace sdfc {

// H above, the "lowbias32" mix: also a cheap deterministic hash for the
// compiler's own sampling (passes/bounds_plan.cpp).
uint32_t mix32(uint32_t h);

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

// The fractal sum's gradient, o octaves: grad N(p) = sum_i grad n(2^i p) / W
// (octave i weighs 0.5^i at frequency 2^i, W = 2 - 2^(1 - o)), so |grad N(p)|
// <= sum_i B(frac(2^i p)) / W. Octave i + 1 sits at frac(2 f_i): the octaves
// cannot all be at the cell's centre, where B peaks (at the centre of one
// octave the next is at a lattice corner, B = sqrt 3). Over a grid of n^3
// cells, with B's largest value over each cell (every factor of B is
// non-negative, so each is taken at its largest over the cell), the most the
// sum reaches along a chain of cells c_0 -> c_1 -> ..., c_(i+1) among the
// 2 x 2 x 2 cells that doubling maps c_i onto, is a bound for every p:
// fractalGradientBoundsByCells(8, n)[o - 1]. kFractalGradientBound is it at
// n = 128, rounded up (tests/lipschitz_test.cpp recomputes it);
// fractalGradientBound takes the least of it and o kNoiseGradientBound / W.
constexpr double kFractalGradientBound[8] = {6.7384, 7.0574, 9.1805, 10.9679, 13.1788, 15.4095, 17.7219, 20.0686};
std::vector<double> fractalGradientBoundsByCells(int octaves, int cells);
double fractalGradientBound(int octaves);

uint32_t noiseHash(int32_t x, int32_t y, int32_t z);
double gradientNoise(const glm::dvec3& p);
double fractalNoise(const glm::dvec3& p, int octaves);

}  // namespace sdfc
