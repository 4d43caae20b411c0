// Passes over the checked scene, run in this order by the driver:
//  fuseTransforms: constant translate/rotate/scale chains become one affine
//                  map; identities vanish.
//  analyze:        per node, conservative bounds, exactness, Lipschitz
//                  constant and evaluation cost (what the emitter's bounding
//                  volumes and step scaling need).
//  rebaseToCamera: (compile only) a far scene moves to the camera's frame.
//  deriveMarchLimits: max distance, step budget and hit epsilon per scene.
#pragma once
#include <functional>
#include "diag/diagnostics.h"
#include "ir/scene.h"

namespace sdfc {

void fuseTransforms(ir::Scene& scene);

// Inline code or data (passes/instancing.cpp): a union's copies of one shape
// become an Instances node when there are at least `threshold` (0: never).
struct InstancingOptions {
  int threshold = 32;
};
void formInstances(ir::Scene& scene, const InstancingOptions& options);
// The hierarchy over an instance set (analyze builds it once bounds are known).
void buildInstanceHierarchy(ir::InstanceSet& set, const ir::Node& n);
// The grid over an instance set (passes/instance_grid.cpp; left empty when it
// would not pay), and its bound at p in float64 given each instance's distance
// (NaN where the cell defers to the hierarchy): what the shader computes.
void buildInstanceGrid(ir::InstanceSet& set, const ir::Node& n);
// A smooth set's grid (passes/blend_grid.cpp) for blend radii up to k, given
// instance i's distance at a point; false (and no grid) where it would not pay.
bool buildBlendGrid(ir::InstanceSet& set, const ir::Node& n, double k,
                    const std::function<double(size_t, const glm::dvec3&)>& distance_of);
ir::GridCellAt instanceGridCellAt(const ir::InstanceGrid& grid, const glm::dvec3& p);
double instanceGridBound(const ir::InstanceSet& set, const glm::dvec3& p,
                         const std::function<double(size_t)>& distance_of);
// How far the ray p + t dir (unit) may go with no instance surface, given a
// lower bound on each instance's first hit (exact for spheres in the shader):
// the cell's exit plus its reach, or a listed hit; 0 outside the grid or in a
// crowded cell. What the shader's root grid writes to g_ray_skip.
double instanceGridRaySkip(const ir::InstanceSet& set, const glm::dvec3& p, const glm::dvec3& dir,
                           const std::function<double(size_t)>& hit_of);
// The box holding b mapped by p -> m * p + t (infinite and empty boxes stay so).
Aabb transformBox(const Aabb& b, const glm::dmat3& m, const glm::dvec3& t);
// Instance i's bounds in its template's frame and in the set's; n is the
// Instances node (its children are the templates).
Aabb instanceLocalBounds(const ir::InstanceSet& set, size_t i, const ir::Node& n);
Aabb instanceBounds(const ir::InstanceSet& set, size_t i, const ir::Node& n);
void analyze(ir::Scene& scene, Diagnostics& diags);
// A scene far from the world origin, seen from near by, is moved to the
// camera's frame (passes/rebase.cpp): scene.origin says where that frame is.
// How far the scene lies from its camera: the distance to the nearest surface
// (float64, at time 0), or to the box around the scene's finite parts where
// that is farther. The camera's frame is wanted where the camera is more than
// 4 times that from the origin.
double sceneDistanceFromCamera(const ir::Scene& scene);
bool wantsCameraFrame(const ir::Scene& scene);
void rebaseToCamera(ir::Scene& scene, Diagnostics& diags);

struct MarchLimits {
  double max_distance = 100;
  int max_steps = 128;
  double hit_epsilon = 1e-4;  // absolute floor
  double pixel_cone = 0;      // epsilon grows by t * this
  double step_scale = 1;      // 1 / Lipschitz constant of the scene
};

struct MarchPolicy {
  bool paper_baseline = false;  // fixed epsilon 1e-3, 256 steps, max distance 100
  int image_height = 0;         // for the pixel-footprint epsilon; 0 = the scene's
};

MarchLimits deriveMarchLimits(const ir::Scene& scene, const MarchPolicy& policy);

// How far a repeat node's child reaches from its cell centre along `axis`
// (infinite when unbounded). Past half a cell, the cells on either side can
// hold the nearest copy: analysis, evaluator and emitter all decide by this.
double repeatReach(const ir::Node& repeat, int axis);
// Whether the child's bounds are off the cell's centre along `axis`.
bool repeatOffCentre(const ir::Node& repeat, int axis);
// The cells on either side are tried too when the child reaches past half a
// cell, or when it sits off the centre: a copy in the next cell can then be
// nearer than the cell's own (cell 2, a copy spanning x in [0.5, 1]: at x =
// -0.9 the own copy is 1.4 away, the next cell's 0.1), and a march stepping by
// the own copy's distance passed through the nearer one. For a child inside
// its cell, the cells beyond those are never nearer (each of their points has
// a nearer twin one cell back), so the three give the exact distance. A child
// whose box is centred is taken from its own cell alone: exact when it is
// symmetric about the centre, not for parts on opposite corners of a centred
// box (docs/language.md says so).
inline bool repeatNeedsNeighbours(const ir::Node& repeat, int axis) {
  const double cell = repeat.vec.value()[axis];
  return cell != 0 && (repeatReach(repeat, axis) > cell / 2 || repeatOffCentre(repeat, axis));
}

// Rotation by `degrees` about unit `axis` (right-handed), as a matrix.
glm::dmat3 rotationMatrix(glm::dvec3 axis, double degrees);

}  // namespace sdfc
