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
// In a cell, with f the point's place in it and o_k the corners,
// n = sum_k w_k(f) g_k . (f - o_k), so grad n = sum_k (w_k g_k + (g_k . (f -
// o_k)) grad w_k), and for a unit direction d, d . grad n = sum_k g_k . v_k
// with v_k = w_k d + (d . grad w_k)(f - o_k). Whatever the hash puts at the
// corners, g_k . v_k is at most the sum of the two largest |v_k,i| (a
// cube-edge gradient has two entries of +-1). Over a box of places, interval
// arithmetic bounds that sum for one d; directions are covered by patches,
// each bounded by its centre's value over cos(its angular radius).
// The largest gradient is 3.75, at the cell's centre along an axis, reached
// by corner gradients that all lean that way (no bound below it holds for
// every cell); cut into 128^3 boxes, the cell's bound is 3.9001. The range:
// |n| <= sum_k w_k (the two largest |f - o_k| components), at most 1.0364.
constexpr double kNoiseRangeBound = 1.05;

// The fractal sum's gradient, o octaves: grad N(p) = sum_i grad n(2^i p) / W
// (octave i weighs 0.5^i at frequency 2^i, W = 2 - 2^(1 - o)), so |grad N(p)|
// <= sum_i B(frac(2^i p)) / W, B bounding one octave at its place. Octave
// i + 1 sits at frac(2 f_i): the octaves cannot all be at the cell's centre,
// where B peaks (at the centre of one octave the next is at a lattice
// corner). Over a grid of n^3 boxes of places, each bounded as above, the
// most the sum reaches along a chain of boxes c_0 -> c_1 -> ..., c_(i+1)
// among the 2 x 2 x 2 that doubling maps c_i onto, is a bound for every p:
// fractalGradientBoundsByCells(8, n)[o - 1]. kFractalGradientBound is it at
// n = 128, rounded up (tests/lipschitz_test.cpp recomputes it).
constexpr double kFractalGradientBound[8] = {3.9002, 4.5250, 5.8114, 7.1235, 8.5867, 10.1009, 11.6648, 13.2501};
std::vector<double> fractalGradientBoundsByCells(int octaves, int cells);
double fractalGradientBound(int octaves);

uint32_t noiseHash(int32_t x, int32_t y, int32_t z);
double gradientNoise(const glm::dvec3& p);
double fractalNoise(const glm::dvec3& p, int octaves);

}  // namespace sdfc
