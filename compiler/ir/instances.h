// Many copies of one shape as data, not code: the instances of a union (or of
// `instances(...)`) that share a template, each with its own rigid placement,
// primitive parameters and material, and a bounding-volume hierarchy over
// them. The evaluator and the emitted shader both visit the hierarchy nearest
// first and stop when no box can hold anything nearer (docs/design/large_scenes.md).
#pragma once
#include <glm/glm.hpp>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "shapes/primitives.h"

namespace sdfc::ir {

// Instance i's template is evaluated at local = linear * p + offset and its
// distance multiplied by scale (as an Affine node); `linear`/`scale` come from
// InstanceSet::transforms[transform], or identity/1 when transform < 0.
struct Instance {
  glm::dvec3 offset{0};
  std::int32_t transform = -1;
  std::int32_t material = -1;  // -1: the material the union passes down
  // Which child of the Instances node this copy is: a set of distinct parts
  // (a mixed set) has one template per primitive kind or definition.
  std::int32_t templ = 0;
};

struct InstanceTransform {
  glm::dmat3 linear{1.0};
  double scale = 1;
};

// A node of the hierarchy. Internal nodes (count == 0) have their left child
// at the next index and their right child at `first`; leaves hold instances
// [first, first + count), count <= kBvhLeafSize.
struct BvhNode {
  Aabb box;
  std::uint32_t first = 0;
  std::uint32_t count = 0;
};

constexpr std::uint32_t kBvhLeafSize = 4;

// A uniform grid over the set (compiler/passes/instance_grid.cpp): cell c
// lists the instances whose boxes lie within `reach[c]` of the cell, at most
// kGridListMax of them, so for p in the cell
//   d = min(min over the list, reach[c] + distance from p to the cell's faces)
// is a lower bound on the set's distance, and exact where the nearest instance
// is listed. A cell too crowded for one list is split into 8 octant sub-cells
// (count kGridSplit, first: the first sub-cell's index, octant x + 2y + 4z,
// stored after the dims.x * dims.y * dims.z cells); a sub-cell still crowded
// (count kGridCrowded) leaves its points to the hierarchy. Outside the grid's
// box every instance is at least `margin` farther than the box.
constexpr int kGridListMax = 8;
// A hard grid's octant crowded at kGridListMax lists up to this many (not a sphere cloud's).
constexpr int kGridListMaxCrowded = 32;
// A blend grid's cells may be split again, down to this many levels.
constexpr int kGridMaxSplits = 3;
// The largest entry index a grid may hold: the shader reads indices as floats,
// exact below 2^24.
constexpr std::size_t kGridMaxEntry = (std::size_t(1) << 24) - 1;
constexpr std::int32_t kGridCrowded = -1;
constexpr std::int32_t kGridSplit = -2;

struct InstanceGrid {
  glm::dvec3 lo{0};
  double cell = 0;           // edge of the cubic cells
  glm::ivec3 dims{0};        // cells per axis; the grid's box is lo + dims * cell
  double margin = 0;
  std::vector<std::uint32_t> first;  // per cell: its list's start in `entries`
  std::vector<std::int32_t> count;   // per cell: list length, kGridCrowded or kGridSplit
  std::vector<double> reach;         // per cell
  std::vector<std::uint32_t> entries;  // instance indices (leaf order)
  // A smooth set's grid (passes/blend_grid.cpp): each cell lists every
  // instance that can come within k of the nearest inside it, so the blend of
  // the list is the blend of the whole set there; no cell is crowded, and
  // `longest` is the longest list. A cell far from every member lists none:
  // there the blend is at least reach[c] + the distance to the cell's faces. Outside the grid's box the
  // blend is at least the distance to the box plus `margin`.
  bool blend = false;
  int longest = 0;
  int splits = 1;  // levels of octants a lookup may descend (the hard grid: at most 1)

  bool empty() const { return count.empty(); }
  size_t cells() const { return count.size(); }  // sub-cells included
};

// Where p (inside the grid's box) is looked up: the cell's index, or its
// octant's if the cell is split; p in that cell's units (0..1 per axis); the
// cell's edge. The shader's arithmetic (passes/instance_grid.cpp).
struct GridCellAt {
  size_t index = 0;
  glm::dvec3 q{0};
  double size = 0;
};

struct InstanceSet {
  std::vector<Instance> instances;  // in leaf order once the hierarchy is built
  std::vector<InstanceTransform> transforms;
  // Per-instance primitive arguments, replacing the template's (the template
  // is then a constant primitive): param_count per instance, flattened. In a
  // mixed set, param_count is the most any primitive template takes, and
  // instances of a definition template carry zeros.
  int param_count = 0;
  std::vector<double> params;
  std::vector<BvhNode> nodes;
  int depth = 0;          // levels of the hierarchy (root alone = 1)
  InstanceGrid grid;      // empty when not built (too big, or a smooth set whose parts move)
  std::string origin;     // what it was formed from, for --emit ir

  size_t size() const { return instances.size(); }
  const double* paramsOf(size_t i) const { return params.data() + i * param_count; }
};

}  // namespace sdfc::ir
