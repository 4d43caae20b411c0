// The float64 signed distance to a triangle mesh: the unsigned distance to the
// nearest triangle through a bounding-volume hierarchy (nearest first, branch
// and bound), signed by the generalized winding number (Jacobson et al. 2013)
// evaluated hierarchically as Barill et al. 2018 do ("Fast winding numbers for
// soups and clouds"): a node far enough away counts as its dipole (the sum of
// its triangles' area vectors at their area-weighted centre), a near one by
// its children, a leaf by exact solid angles. docs/mesh_in.md says why and
// where it fails.
#pragma once
#include <glm/glm.hpp>
#include <cstdint>
#include <vector>

#include "meshin/mesh_file.h"
#include "shapes/primitives.h"

namespace sdfc {

struct MeshBvhNode {
  Aabb box;
  std::uint32_t first = 0;  // internal (count 0): the right child; the left is next
  std::uint32_t count = 0;  // leaf: triangles [first, first + count)
  // The dipole: area-weighted centre, sum of area vectors (half cross
  // products), and the radius about the centre that holds every corner.
  glm::dvec3 centre{0}, area{0};
  double radius = 0;
};

constexpr std::uint32_t kMeshLeafSize = 4;
// A node counts as its dipole when the point is farther than this times its
// radius from its centre (Barill et al.'s beta; 2 keeps the error near 1e-3).
constexpr double kWindingFarFactor = 2.0;

class MeshDistance {
 public:
  explicit MeshDistance(const InputMesh& mesh);

  // Distance to the nearest triangle, or `cap` when none is nearer than that.
  double unsignedDistance(const glm::dvec3& p, double cap = 1e300) const;
  // About 1 inside a closed, outward-facing mesh, 0 outside, fractional near holes.
  double winding(const glm::dvec3& p) const;
  // Negative where the winding number is above one half.
  double signedDistance(const glm::dvec3& p) const;

  const Aabb& bounds() const { return nodes_[0].box; }
  size_t triangleCount() const { return corners_.size() / 3; }
  const std::vector<MeshBvhNode>& nodes() const { return nodes_; }
  // Triangle t's corners (leaf order): corners()[3t .. 3t + 2].
  const std::vector<glm::dvec3>& corners() const { return corners_; }
  int depth() const { return depth_; }

 private:
  std::vector<glm::dvec3> corners_;
  std::vector<MeshBvhNode> nodes_;
  int depth_ = 0;
};

// The distance from p to triangle abc (no sign).
double pointTriangleDistance(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c);
// The solid angle triangle abc subtends at p, positive when p sees its back
// (counter-clockwise abc faces away): Van Oosterom and Strackee 1983.
double triangleSolidAngle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c);

}  // namespace sdfc
