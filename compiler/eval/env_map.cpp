#include "eval/env_map.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "eval/shared_exponent.h"

namespace sdfc {
namespace {

constexpr float kPi = 3.14159265358979f;

float luminance(const glm::vec3& c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }

// The first index in cdf[0, n) whose value exceeds u (cdf ends at 1 > u): as
// the kernel's loop, a fixed log2(n) + 1 halvings.
int findInterval(const float* cdf, int n, float u) {
  int lo = 0, hi = n - 1;
  while (lo < hi) {
    const int mid = (lo + hi) / 2;
    if (cdf[mid] > u) hi = mid;
    else lo = mid + 1;
  }
  return lo;
}

}  // namespace

EnvMapData buildEnvMap(const ir::TextureImage& image, bool uniform) {
  EnvMapData m;
  m.width = image.width;
  m.height = image.height;
  m.cells_x = m.width - 1;
  m.cells_y = m.height - 1;
  const size_t n = size_t(m.width) * m.height;
  float peak = 0;
  for (float v : image.rgb) peak = std::max(peak, v);
  // The peak stored near the top of the shared exponent's range: every
  // texel within 2^30 of it keeps its 9 bits (dim maps and bright ones).
  if (peak > 0) m.scale = peak / kSharedExponentMax;  // (packing clamps a rounding above)
  const float inv_scale = 1.0f / m.scale;
  m.texels.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const float* c = &image.rgb[3 * i];
    m.texels[i] = packSharedExponent(glm::vec3(c[0], c[1], c[2]) * inv_scale);
  }
  // A texel cell lies between four texel centres; its weight is their mean
  // luminance as stored (the kernel's radiance), so that it is positive
  // wherever the bilinear radiance is. A grid cell's weight is the mean of
  // the texel cells' over its area (exact integer overlaps: the identity when
  // the grid is the texel cells), times sin(theta) at its centre; it is
  // positive wherever the radiance in it is. A black map falls back to
  // uniform weights, keeping its CDFs defined (its samples carry no light).
  m.grid_x = std::min(m.cells_x, kEnvGridMaxX);
  m.grid_y = std::min(m.cells_y, kEnvGridMaxY);
  std::vector<double> lum(n);
  for (int y = 0; y < m.height; ++y)
    for (int x = 0; x < m.width; ++x) lum[size_t(y) * m.width + x] = luminance(envMapTexel(m, x, y));
  // Texel cells [first, last] overlapping grid cell g of `grid` over `cells`,
  // and their overlaps in units of 1 / (cells * grid).
  auto overlaps = [](int g, int cells, int grid, auto&& use) {
    const int first = int(int64_t(g) * cells / grid), last = int((int64_t(g + 1) * cells + grid - 1) / grid) - 1;
    for (int c = first; c <= std::min(last, cells - 1); ++c) {
      const int64_t o = std::min(int64_t(c + 1) * grid, int64_t(g + 1) * cells) - std::max(int64_t(c) * grid, int64_t(g) * cells);
      if (o > 0) use(c, double(o));
    }
  };
  // Row by row of texel cells: their weights summed into the grid's columns.
  std::vector<double> by_column(size_t(m.cells_y) * m.grid_x, 0.0);
  for (int y = 0; y < m.cells_y; ++y)
    for (int gx = 0; gx < m.grid_x; ++gx)
      overlaps(gx, m.cells_x, m.grid_x, [&](int x, double o) {
        const size_t t = size_t(y) * m.width + x;
        by_column[size_t(y) * m.grid_x + gx] += o * 0.25 * (lum[t] + lum[t + 1] + lum[t + m.width] + lum[t + m.width + 1]);
      });
  const size_t cells = size_t(m.grid_x) * m.grid_y;
  std::vector<double> weights(cells, 0.0), row_sum(m.grid_y, 0.0);
  for (int gy = 0; gy < m.grid_y; ++gy) {
    const double sin_theta = std::sin(M_PI * (gy + 0.5) / m.grid_y);
    double area = 0;
    overlaps(gy, m.cells_y, m.grid_y, [&](int y, double o) {
      area += o;
      for (int gx = 0; gx < m.grid_x; ++gx) weights[size_t(gy) * m.grid_x + gx] += o * by_column[size_t(y) * m.grid_x + gx];
    });
    // A grid column's overlaps sum to cells_x units, a row's to `area`.
    const double norm = 1.0 / (area * m.cells_x);
    for (int gx = 0; gx < m.grid_x; ++gx) {
      double& w = weights[size_t(gy) * m.grid_x + gx];
      w = (uniform ? 1.0 : w * norm) * sin_theta;
      row_sum[gy] += w;
    }
    m.total_weight += row_sum[gy];
  }
  if (m.total_weight <= 0) {
    for (int y = 0; y < m.grid_y; ++y) {
      row_sum[y] = 0;
      for (int x = 0; x < m.grid_x; ++x) row_sum[y] += weights[size_t(y) * m.grid_x + x] = 1;
    }
  }
  m.column_cdf.resize(cells);
  for (int y = 0; y < m.grid_y; ++y) {
    double acc = 0;
    float* row = &m.column_cdf[size_t(y) * m.grid_x];
    for (int x = 0; x < m.grid_x; ++x) {
      acc += weights[size_t(y) * m.grid_x + x];
      // A row of weight 0 is never drawn and its pdf is 0 whatever its
      // columns are: uniform ones keep its CDF increasing.
      row[x] = row_sum[y] > 0 ? float(acc / row_sum[y]) : float(double(x + 1) / m.grid_x);
    }
    row[m.grid_x - 1] = 1.0f;
  }
  double total = 0;
  for (double r : row_sum) total += r;
  m.row_cdf.resize(m.grid_y);
  double acc = 0;
  for (int y = 0; y < m.grid_y; ++y) {
    acc += row_sum[y];
    m.row_cdf[y] = float(acc / total);
  }
  m.row_cdf[m.grid_y - 1] = 1.0f;
  return m;
}

glm::vec3 envMapTexel(const EnvMapData& m, int x, int y) {
  return unpackSharedExponent(m.texels[size_t(y) * m.width + x]);
}

namespace {
glm::vec2 uvOf(const glm::vec3& d) {
  float u = std::atan2(d.x, -d.z) / (2 * kPi);
  u -= std::floor(u);
  return {u, std::acos(std::clamp(d.y, -1.0f, 1.0f)) / kPi};
}
}  // namespace

glm::vec3 envMapRadiance(const EnvMapData& m, const glm::vec3& d) {
  const glm::vec2 uv = uvOf(d);
  const float s = uv.x * float(m.cells_x), t = uv.y * float(m.cells_y);
  const int x0 = std::min(int(s), m.cells_x - 1), y0 = std::min(int(t), m.cells_y - 1);
  const float a = s - float(x0), b = t - float(y0);
  const glm::vec3 top = glm::mix(envMapTexel(m, x0, y0), envMapTexel(m, x0 + 1, y0), a);
  const glm::vec3 bottom = glm::mix(envMapTexel(m, x0, y0 + 1), envMapTexel(m, x0 + 1, y0 + 1), a);
  return glm::mix(top, bottom, b) * m.scale;
}

bool sampleEnvMap(const EnvMapData& m, glm::vec2 u, glm::vec3& dir, float& pdf) {
  pdf = 0;
  const int y = findInterval(m.row_cdf.data(), m.grid_y, u.y);
  const float r0 = y > 0 ? m.row_cdf[y - 1] : 0.0f, p_row = m.row_cdf[y] - r0;
  const float* row = &m.column_cdf[size_t(y) * m.grid_x];
  const int x = findInterval(row, m.grid_x, u.x);
  const float c0 = x > 0 ? row[x - 1] : 0.0f, p_col = row[x] - c0;
  if (p_row <= 0 || p_col <= 0) return false;
  const float uu = (float(x) + (u.x - c0) / p_col) / float(m.grid_x);
  const float vv = (float(y) + (u.y - r0) / p_row) / float(m.grid_y);
  const float theta = kPi * vv, phi = 2 * kPi * uu;
  const float sin_theta = std::sin(theta);
  if (sin_theta <= 0) return false;
  dir = glm::vec3(sin_theta * std::sin(phi), std::cos(theta), -sin_theta * std::cos(phi));
  pdf = p_row * p_col * float(m.grid_x) * float(m.grid_y) / (2 * kPi * kPi * sin_theta);
  return true;
}

float envMapPdf(const EnvMapData& m, const glm::vec3& d) {
  const glm::vec2 uv = uvOf(d);
  const int x = std::min(int(uv.x * m.grid_x), m.grid_x - 1), y = std::min(int(uv.y * m.grid_y), m.grid_y - 1);
  const float p_row = m.row_cdf[y] - (y > 0 ? m.row_cdf[y - 1] : 0.0f);
  const float* row = &m.column_cdf[size_t(y) * m.grid_x];
  const float p_col = row[x] - (x > 0 ? row[x - 1] : 0.0f);
  const float sin_theta = std::sqrt(d.x * d.x + d.z * d.z);
  if (sin_theta <= 0) return 0;
  return p_row * p_col * float(m.grid_x) * float(m.grid_y) / (2 * kPi * kPi * sin_theta);
}

}  // namespace sdfc
