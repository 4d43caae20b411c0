// The environment light sky(map: ...): its data for the kernel and the
// piecewise-constant 2D distribution next-event estimation samples it by
// (marginal rows, then a column in the row; Pharr, Jakob and Humphreys,
// "Physically Based Rendering", 4th ed., sec. 12.5.2), weighted by luminance
// times sin(theta) so that directions are drawn in proportion to their power.
// The sampling functions here are the CPU twin of kernel/envmap.glsl, in
// float32 as the kernel does it: the tests check the kernel's sampling
// against its pdf through them (tests/env_map_test.cpp).
//
// Directions are of the map's own frame (rotation applied by the caller),
// y up, as Mitsuba 3's envmap: u = atan2(x, -z) / 2 pi, v = acos(y) / pi,
// and texel (i, j) (j from the top) at u = i / (W - 1), v = j / (H - 1): the
// first and last columns both on the seam, the top row at the zenith.
// Radiance is bilinear between the four texels around a direction. The
// distribution is over a grid of at most kEnvGridMaxX x kEnvGridMaxY equal
// cells in (u, v): the (W - 1) x (H - 1) cells between texels for a map up
// to 513 x 257, coarser cells (each weighted by the mean of the texel cells
// it covers) for a larger one, so that sampling reads a table that stays in
// cache whatever the map's size; a direction is drawn uniformly in its cell,
// and its pdf is that cell's.
#pragma once
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "ir/scene.h"

namespace sdfc {

constexpr int kEnvGridMaxX = 512, kEnvGridMaxY = 256;

struct EnvMapData {
  int width = 0, height = 0;
  int cells_x = 0, cells_y = 0;  // width - 1, height - 1
  // The sampling grid: min(cells_x, kEnvGridMaxX) x min(cells_y, kEnvGridMaxY).
  int grid_x = 0, grid_y = 0;
  // Stored texel * scale = radiance: the map is stored with its peak near
  // the shared exponent's largest value (32704), whatever its brightness.
  float scale = 1;
  // One word a texel, rows from the top: packSharedExponent(r, g, b).
  std::vector<uint32_t> texels;
  // grid_x * grid_y: row by row, the CDF of the grid's cells to the end of
  // each (the last of a row is 1); then grid_y: the CDF of the rows.
  std::vector<float> column_cdf, row_cdf;
  // The sum of the weights (mean luminance * sin(theta) a grid cell): 0 for a black map.
  double total_weight = 0;
};

// uniform: weights sin(theta) alone, i.e. directions uniform over the sphere
// (bench/env_map.py's baseline; SDFC_ENVMAP_SAMPLING=uniform at compile time).
EnvMapData buildEnvMap(const ir::TextureImage& image, bool uniform = false);

// The stored radiance of texel (x, y), y from the top (before scale).
glm::vec3 envMapTexel(const EnvMapData& map, int x, int y);
// Radiance toward dir, bilinear (scale applied; strength not).
glm::vec3 envMapRadiance(const EnvMapData& map, const glm::vec3& dir);
// A direction drawn from the distribution by u in [0, 1)^2, with its solid-
// angle pdf; false where nothing can be drawn (a cell of probability 0).
bool sampleEnvMap(const EnvMapData& map, glm::vec2 u, glm::vec3& dir, float& pdf);
// The solid-angle pdf of sampleEnvMap drawing dir.
float envMapPdf(const EnvMapData& map, const glm::vec3& dir);

}  // namespace sdfc
