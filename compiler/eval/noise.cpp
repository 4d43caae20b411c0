#include "eval/noise.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace sdfc {

uint32_t mix32(uint32_t h) {
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  return h;
}

namespace {

const glm::dvec3 kGradients[12] = {{1, 1, 0},  {-1, 1, 0},  {1, -1, 0}, {-1, -1, 0},
                                   {1, 0, 1},  {-1, 0, 1},  {1, 0, -1}, {-1, 0, -1},
                                   {0, 1, 1},  {0, -1, 1},  {0, 1, -1}, {0, -1, -1}};

double fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }

}  // namespace

uint32_t noiseHash(int32_t x, int32_t y, int32_t z) {
  return mix32(uint32_t(x) ^ mix32(uint32_t(y) ^ mix32(uint32_t(z))));
}

double gradientNoise(const glm::dvec3& p) {
  const glm::dvec3 c = glm::floor(p);
  const glm::dvec3 f = p - c;
  const glm::ivec3 i(c);
  double corner[8];
  for (int k = 0; k < 8; ++k) {
    const glm::ivec3 o(k & 1, (k >> 1) & 1, (k >> 2) & 1);
    const glm::dvec3 g = kGradients[noiseHash(i.x + o.x, i.y + o.y, i.z + o.z) % 12u];
    corner[k] = glm::dot(g, f - glm::dvec3(o));
  }
  const glm::dvec3 u(fade(f.x), fade(f.y), fade(f.z));
  auto lerp = [](double a, double b, double t) { return a + (b - a) * t; };
  const double x00 = lerp(corner[0], corner[1], u.x), x10 = lerp(corner[2], corner[3], u.x);
  const double x01 = lerp(corner[4], corner[5], u.x), x11 = lerp(corner[6], corner[7], u.x);
  return lerp(lerp(x00, x10, u.y), lerp(x01, x11, u.y), u.z);
}

double fractalNoise(const glm::dvec3& p, int octaves) {
  double sum = 0, weight = 0, amplitude = 1, frequency = 1;
  for (int i = 0; i < octaves; ++i) {
    sum += amplitude * gradientNoise(p * frequency);
    weight += amplitude;
    amplitude *= 0.5;
    frequency *= 2;
  }
  return weight > 0 ? sum / weight : 0;
}

namespace {

struct Range {
  double lo, hi;
};

// fade and its derivative over [a, b] within [0, 1]: fade rises; fade' rises
// to its peak 1.875 at 0.5 and falls after.
Range fadeOver(double a, double b) { return {fade(a), fade(b)}; }
Range dfadeOver(double a, double b) {
  auto d = [](double t) { return 30 * t * t * (1 - t) * (1 - t); };
  const double x = d(a), y = d(b);
  return {std::min(x, y), a <= 0.5 && b >= 0.5 ? d(0.5) : std::max(x, y)};
}

// The most B_x (noise.h) takes over the box [x0, x1] x [y0, y1] x [z0, z1]:
// every factor of each term is non-negative, so each is replaced by its
// largest value over the box.
double axisBoundOver(double x0, double x1, double y0, double y1, double z0, double z1) {
  const Range u = fadeOver(x0, x1), du = dfadeOver(x0, x1);
  auto largestAbs = [](double lo, double hi) { return std::max(std::fabs(lo), std::fabs(hi)); };
  // alpha_0 = 1 - u - u' x and alpha_1 = u - u' (1 - x), each term's extremes.
  const double alpha[2] = {largestAbs(1 - u.hi - du.hi * x1, 1 - u.lo - du.lo * x0),
                           largestAbs(u.lo - du.hi * (1 - x0), u.hi - du.lo * (1 - x1))};
  const Range fy = fadeOver(y0, y1), fz = fadeOver(z0, z1);
  double total = 0;
  for (int oy = 0; oy < 2; ++oy)
    for (int oz = 0; oz < 2; ++oz) {
      const double dy = oy ? 1 - y0 : y1, dz = oz ? 1 - z0 : z1;
      const double w = (oy ? fy.hi : 1 - fy.lo) * (oz ? fz.hi : 1 - fz.lo);
      for (int o = 0; o < 2; ++o) total += w * std::max(alpha[o] + du.hi * std::max(dy, dz), du.hi * (dy + dz));
    }
  return total;
}

}  // namespace

std::vector<double> fractalGradientBoundsByCells(int octaves, int cells) {
  const int n = cells;
  const double h = 1.0 / n;
  std::vector<double> cell(size_t(n) * n * n), sum, next(cell.size());
  auto at = [n](int i, int j, int k) { return (size_t(i) * n + j) * n + k; };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        const double x0 = i * h, y0 = j * h, z0 = k * h, x1 = x0 + h, y1 = y0 + h, z1 = z0 + h;
        const double bx = axisBoundOver(x0, x1, y0, y1, z0, z1), by = axisBoundOver(y0, y1, x0, x1, z0, z1),
                     bz = axisBoundOver(z0, z1, y0, y1, x0, x1);
        cell[at(i, j, k)] = std::sqrt(bx * bx + by * by + bz * bz);
      }
  // sum[c]: the most o octaves' bounds add up to when the first of them lies
  // in cell c (so bounds[o - 1] is its largest over W); the next octave then lies in the 2 x 2 x 2 cells
  // that doubling maps c onto (mod 1).
  sum = cell;
  std::vector<double> bounds;
  for (int o = 1;; ++o) {
    bounds.push_back(*std::max_element(sum.begin(), sum.end()) / (2 - std::ldexp(1.0, 1 - o)));
    if (o == octaves) return bounds;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k) {
          double most = 0;
          for (int a = 0; a < 8; ++a)
            most = std::max(most, sum[at((2 * i + (a & 1)) % n, (2 * j + (a >> 1 & 1)) % n, (2 * k + (a >> 2)) % n)]);
          next[at(i, j, k)] = cell[at(i, j, k)] + most;
        }
    std::swap(sum, next);
  }
}

double fractalGradientBound(int octaves) {
  if (octaves < 1) return 0;
  const int o = std::min(octaves, 8);
  return std::min(kFractalGradientBound[o - 1], o * kNoiseGradientBound / (2 - std::ldexp(1.0, 1 - o)));
}

}  // namespace sdfc
