// Passes over the checked scene, run in this order by the driver:
//  fuseTransforms: constant translate/rotate/scale chains become one affine
//                  map; identities vanish.
//  analyze:        per node, conservative bounds, exactness, Lipschitz
//                  constant and evaluation cost (what the emitter's bounding
//                  volumes and step scaling need).
//  rebaseToCamera: (compile only) a far scene moves to the camera's frame.
//  deriveMarchLimits: max distance, step budget and hit epsilon per scene.
#pragma once
#include <algorithm>
#include <cmath>
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
// instance i's distance at a point (called from several threads at once);
// false (and no grid) where it would not pay. `threads`: 0 = as many as the
// machine has for a large grid; any count builds the same grid, bit for bit.
bool buildBlendGrid(ir::InstanceSet& set, const ir::Node& n, double k,
                    const std::function<double(size_t, const glm::dvec3&)>& distance_of, unsigned threads = 0);
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
// The most a subtree's field is divided by on its way down (twist, bend and
// displace divide theirs by their stretch): a bounding-volume check's box
// distance is divided by it too (the emitter, passes/bounds_plan.cpp).
double stretchBelow(const ir::Node& n);
// Whether a union may guard child c with its box (emitter, bounds plan), and
// the margin beyond which the box distance stands in for the child's own.
inline bool boxCheckCandidate(const ir::Node& c, double cost_threshold) {
  return c.cost >= cost_threshold && c.bounds.finite();
}
// (Beyond what the nodes above may take off it too: ir::Node::lowered.)
inline double boxCheckMargin(const ir::Node& c) {
  return std::max(0.1 * glm::length(c.bounds.halfSize()), std::min(1.01 * c.lowered, 1e30));
}
// Whether `n` hands its child's distance up unchanged: a translation, a
// rotation, a reflection, a rigid transform. A hard union's cut (what it has so
// far, which the emitter passes down to a nested hard union's box checks)
// holds through it.
inline bool keepsDistances(const ir::Node& n) {
  if (n.kind == ir::NodeKind::Translate || n.kind == ir::NodeKind::Rotate || n.kind == ir::NodeKind::Reflect)
    return true;
  if (n.kind != ir::NodeKind::Affine || n.scale != 1) return false;
  const glm::dmat3 gram = glm::transpose(n.linear) * n.linear;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (std::abs(gram[i][j] - (i == j ? 1.0 : 0.0)) > 1e-9) return false;
  return true;
}
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

// Which unions' children get a bounding-volume check on a device that runs
// lanes in lockstep (passes/bounds_plan.cpp): marks Node::box_check where the
// float64 march from the camera says it saves more than it costs. `budget`
// caps the sampling work (in primitive evaluations).
struct BoundsPlan {
  int tiles = 0, candidates = 0, checks = 0;
  double group_steps = 0, work = 0, saved = 0;
};
BoundsPlan planBoundChecks(ir::Scene& scene, const MarchPolicy& policy, double cost_threshold,
                           double budget = 4e6);

// Lipschitz pruning of the root union (passes/prune_grid.cpp): a grid whose
// cells list the parts that can be nearest there (Node::prune on the root),
// where at least two parts can be pruned. Opt-in (`--prune`): on lavapipe
// the cell's lookup costs more than it saves (bench/results/prune_grid.md).
void planPruneGrid(ir::Scene& scene);
// The grid alone (null where fewer than two parts can be pruned), for the
// float64 block evaluator (`mesh`, many-point `eval`), and the mask of p's cell.
std::shared_ptr<const ir::PruneGrid> buildPruneGrid(const ir::Scene& scene);
std::array<std::uint32_t, 4> pruneMaskAt(const ir::PruneGrid& g, const glm::dvec3& p);

// How far a repeat node's child reaches from its cell centre along `axis`
// (infinite when unbounded).
double repeatReach(const ir::Node& repeat, int axis);
// Whether the child's bounds are off the cell's centre along `axis`.
bool repeatOffCentre(const ir::Node& repeat, int axis);

// The copies of a repeat's child tried along one axis: the one whose centre
// (the child's box centre, moved by whole cells) is nearest the point, and
// `side` more on either side. Analysis, evaluator and emitter all use this.
//
// Why it is exact: with the child's box of half-width h about its centre m,
// a point in the window of copy i (|x - m - c i| <= c / 2) and a copy j >= i +
// 1 + h / c, every point s of copy j has a twin s - c in copy j - 1 that is
// nearer (x <= s - c / 2), and the same on the other side; so the copies within
// ceil(h / c) of i hold the nearest one (issue 49: a child far off its cell's
// centre was taken from the wrong cells, up to 16x too far, copies vanishing).
// A child whose box is centred and within half a cell, and that is its own
// mirror image across the cell's centre plane (mirrorSymmetric), is taken from
// its own cell alone: the mirror image of a point of the next copy across the
// cells' shared face is a point of the own copy, on the side of the query
// point. Any other centred child (a rotated torus, parts on opposite corners
// of a centred box) tries the cells on either side too. An unbounded
// child tries one cell on either side of its own, a bound (warned).
// `side` is at most kRepeatMaxSide: a child wider than that many cells keeps
// only those (warned, the distance may be too large there).
constexpr int kRepeatMaxSide = 2;
// Whether the shape is its own mirror image across the plane through the
// origin normal to `axis` (false when not known).
bool mirrorSymmetric(const ir::Node& n, int axis);
struct RepeatCells {
  int side = 0;        // copies tried on either side of the nearest
  double centre = 0;   // m: the child's box centre along the axis (0 unbounded)
  bool covered = true; // every copy that can be nearest is tried
  double half = 0;     // h: the child's box half-width (copies overlap past c / 2)
};
RepeatCells repeatCells(const ir::Node& repeat, int axis);
inline bool repeatNeedsNeighbours(const ir::Node& repeat, int axis) { return repeatCells(repeat, axis).side > 0; }

// The same for repeat_polar: the sectors first..last (relative to the one
// whose copy's angular centre is nearest the point's angle, `centre` radians
// about y from +x, as atan2(z, x)) hold the nearest copy, by the same twin
// argument in angle (same radius and height, nearer in angle is nearer). A
// child whose box holds the axis spans every angle: all copies, up to
// kPolarMaxSectors.
constexpr int kPolarMaxSectors = 33;
struct PolarSectors {
  int first = -1, last = 1;
  double centre = 0;
  bool covered = true;
  double half = 0;  // the half angle the child spans (copies overlap past pi / count)
};
PolarSectors polarSectors(const ir::Node& repeat_polar);

// Rotation by `degrees` about unit `axis` (right-handed), as a matrix.
glm::dmat3 rotationMatrix(glm::dvec3 axis, double degrees);

}  // namespace sdfc
