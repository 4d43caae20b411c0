#include "eval/noise.h"

#include <cmath>

namespace sdfc {
namespace {

uint32_t mix32(uint32_t h) {
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  return h;
}

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

}  // namespace sdfc
