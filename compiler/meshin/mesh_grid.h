// The sampled form of a mesh for the shader: its signed distance at the
// corners of a uniform grid over its box (a narrow band: values beyond
// `band` are clamped to it), read with trilinear interpolation; outside the
// grid, the distance to the mesh's box. The trilinear weights of a point's
// eight corners put their squared distances to it at most 3h^2/4 on average,
// so interpolating a 1-Lipschitz distance errs by at most (sqrt 3 / 2) h
// (Jensen's inequality); the interpolant's own Lipschitz constant is at most
// sqrt 3 (each axis' slope at most 1).
#pragma once
#include <glm/glm.hpp>
#include <vector>

#include "shapes/primitives.h"

namespace sdfc {

class MeshDistance;

// Cells along the box's longest side (and kMeshGridPad more each side).
constexpr int kMeshGridCells = 96;
constexpr int kMeshGridPad = 2;
// The band, in cells: beyond it a value is only a lower bound (clamped).
constexpr double kMeshGridBand = 3;

struct MeshGridLayout {
  glm::dvec3 lo{0};
  double cell = 0;
  glm::ivec3 dims{0};  // corners per axis
  double band = 0;
  Aabb mesh_box;
  double errorBound() const { return 0.8660254037844386 * cell; }
  size_t corners() const { return size_t(dims.x) * dims.y * dims.z; }
};

struct MeshGrid {
  std::vector<float> values;  // x fastest, then y, then z
  size_t winding_queries = 0;  // how many corners needed their own winding number
  double build_seconds = 0;
  bool from_cache = false;  // read from the on-disk cache (meshin/mesh_grid_cache.h)
};

MeshGridLayout meshGridLayout(const Aabb& mesh_box, int cells = kMeshGridCells);
MeshGrid buildMeshGrid(const MeshDistance& mesh, const MeshGridLayout& layout);

// The GLSL that reads a grid written by appendMeshGridData: sdMeshGrid(p, base).
const char* meshGridGlsl();
// Appends the header and values (vec4s) to `data`; returns the header's vec4 index.
size_t appendMeshGridData(const MeshGridLayout& layout, const MeshGrid& grid, std::vector<float>& data);

}  // namespace sdfc
