// Many copies of one shape as data, not code: the instances of a union (or of
// `instances(...)`) that share a template, each with its own rigid placement,
// primitive parameters and material, and a bounding-volume hierarchy over
// them. The evaluator and the emitted shader both visit the hierarchy nearest
// first and stop when no box can hold anything nearer (docs/large_scenes.md).
#pragma once
#include <glm/glm.hpp>
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

struct InstanceSet {
  std::vector<Instance> instances;  // in leaf order once the hierarchy is built
  std::vector<InstanceTransform> transforms;
  // Per-instance primitive arguments, replacing the template's (the template
  // is then a constant primitive): param_count per instance, flattened.
  int param_count = 0;
  std::vector<double> params;
  std::vector<BvhNode> nodes;
  int depth = 0;          // levels of the hierarchy (root alone = 1)
  std::string origin;     // what it was formed from, for --emit ir

  size_t size() const { return instances.size(); }
  const double* paramsOf(size_t i) const { return params.data() + i * param_count; }
};

}  // namespace sdfc::ir
