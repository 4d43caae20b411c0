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

// Closed intervals and the arithmetic the bound needs.
struct Range {
  double lo, hi;
};
Range operator+(Range a, Range b) { return {a.lo + b.lo, a.hi + b.hi}; }
Range operator*(Range a, Range b) {
  const double p[4] = {a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi};
  return {*std::min_element(p, p + 4), *std::max_element(p, p + 4)};
}
Range operator*(Range a, double s) { return s >= 0 ? Range{a.lo * s, a.hi * s} : Range{a.hi * s, a.lo * s}; }
double largestAbs(Range a) { return std::max(std::fabs(a.lo), std::fabs(a.hi)); }

// fade and its derivative over [a, b] within [0, 1]: fade rises; fade' rises
// to its peak 1.875 at 0.5 and falls after.
Range fadeOver(double a, double b) { return {fade(a), fade(b)}; }
Range dfadeOver(double a, double b) {
  auto d = [](double t) { return 30 * t * t * (1 - t) * (1 - t); };
  const double x = d(a), y = d(b);
  return {std::min(x, y), a <= 0.5 && b >= 0.5 ? d(0.5) : std::max(x, y)};
}

// One corner's weight w and its gradient over a box of the cell, and the
// box's offsets from the corner.
struct CornerRanges {
  Range w, dw[3], offset[3];
};

// noise.h's bound: the directions d are cut into patches (the squares of a
// grid on each face of the cube [-1, 1]^3, projected), each bounded by
// sup_v d_P . v / cos(rho_P), rho_P the patch's angular radius; a patch whose
// bound is more than 0.2% above the best d . v seen is cut in four.
double gradientBoundOverBox(const glm::dvec3& lo, const glm::dvec3& hi) {
  CornerRanges c[8];
  Range u[3], du[3];
  for (int a = 0; a < 3; ++a) {
    u[a] = fadeOver(lo[a], hi[a]);
    du[a] = dfadeOver(lo[a], hi[a]);
  }
  for (int k = 0; k < 8; ++k) {
    Range w[3], dw[3];
    for (int a = 0; a < 3; ++a) {
      const bool far = k >> a & 1;
      w[a] = far ? u[a] : Range{1 - u[a].hi, 1 - u[a].lo};
      dw[a] = far ? du[a] : Range{-du[a].hi, -du[a].lo};
      c[k].offset[a] = {lo[a] - far, hi[a] - far};
    }
    c[k].w = w[0] * w[1] * w[2];
    c[k].dw[0] = dw[0] * w[1] * w[2];
    c[k].dw[1] = w[0] * dw[1] * w[2];
    c[k].dw[2] = w[0] * w[1] * dw[2];
  }
  // The most d . grad n reaches over the box for unit d: each corner's term
  // is g . v with v = w d + (d . grad w)(f - o), and a cube-edge g makes that
  // at most the two largest |v_i|.
  auto support = [&](const glm::dvec3& d) {
    double total = 0;
    for (const CornerRanges& k : c) {
      const Range along = k.dw[0] * d.x + k.dw[1] * d.y + k.dw[2] * d.z;
      double m[3];
      for (int a = 0; a < 3; ++a) m[a] = largestAbs(k.w * d[a] + along * k.offset[a]);
      total += m[0] + m[1] + m[2] - std::min({m[0], m[1], m[2]});
    }
    return total;
  };
  struct Patch {
    int face;
    double a, b, side, bound;
  };
  double best = 0;
  auto bound = [&](Patch& p) {
    glm::dvec3 q;
    const int axis = p.face / 2;
    q[axis] = p.face & 1 ? 1 : -1;
    q[(axis + 1) % 3] = p.a;
    q[(axis + 2) % 3] = p.b;
    const double len = glm::length(q), s = support(q / len);
    best = std::max(best, s);
    // Every point of the square lies within side / sqrt 2 of its centre q,
    // and |q| >= 1: sin(rho) <= that over |q|.
    const double sin_rho = p.side / std::sqrt(2.0) / len;
    p.bound = s / std::sqrt(1 - sin_rho * sin_rho);
  };
  std::vector<Patch> open;
  constexpr int kStart = 4;
  for (int face = 0; face < 6; ++face)
    for (int i = 0; i < kStart; ++i)
      for (int j = 0; j < kStart; ++j) {
        Patch p{face, -1 + (i + 0.5) * 2 / kStart, -1 + (j + 0.5) * 2 / kStart, 2.0 / kStart, 0};
        bound(p);
        open.push_back(p);
      }
  double most = 0;
  while (!open.empty()) {
    const Patch p = open.back();
    open.pop_back();
    if (p.bound <= best * 1.002) {
      most = std::max(most, p.bound);
      continue;
    }
    const double q = p.side / 4;
    for (int k = 0; k < 4; ++k) {
      Patch child{p.face, p.a + (k & 1 ? q : -q), p.b + (k & 2 ? q : -q), p.side / 2, 0};
      bound(child);
      open.push_back(child);
    }
  }
  return most;
}

// The noise's gradient bound is the same for a cell's images under the
// cube's symmetries (reflections x -> 1 - x and exchanges of axes map the
// corners and the 12 gradients onto themselves): one representative each.
std::vector<double> cellGradientBounds(int n) {
  auto at = [n](int i, int j, int k) { return (size_t(i) * n + j) * n + k; };
  std::vector<double> cells(size_t(n) * n * n, -1);
  const double h = 1.0 / n;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        int r[3] = {std::min(i, n - 1 - i), std::min(j, n - 1 - j), std::min(k, n - 1 - k)};
        std::sort(r, r + 3);
        double& rep = cells[at(r[0], r[1], r[2])];
        if (rep < 0) rep = gradientBoundOverBox(glm::dvec3(r[0], r[1], r[2]) * h, glm::dvec3(r[0] + 1, r[1] + 1, r[2] + 1) * h);
        cells[at(i, j, k)] = rep;
      }
  return cells;
}

}  // namespace

std::vector<double> fractalGradientBoundsByCells(int octaves, int cells) {
  const int n = cells;
  const std::vector<double> cell = cellGradientBounds(n);
  auto at = [n](int i, int j, int k) { return (size_t(i) * n + j) * n + k; };
  // sum[c]: the most o octaves' bounds add up to when the first of them lies
  // in cell c (so bounds[o - 1] is its largest over W); the next octave then
  // lies in the 2 x 2 x 2 cells that doubling maps c onto (mod 1).
  std::vector<double> sum = cell, next(cell.size()), bounds;
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
  return kFractalGradientBound[std::min(octaves, 8) - 1];
}

}  // namespace sdfc
