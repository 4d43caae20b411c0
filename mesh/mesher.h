// Triangle meshes from checked scenes: a uniform grid over the scene's
// compiler bounds, signs sampled with the float64 evaluator, and dual
// contouring (Ju, Losasso, Schaefer, Warren 2002, "Dual Contouring of
// Hermite Data") so CSG edges and box corners stay sharp.
//
// Known limits: features thinner than a voxel can vanish, and sheets of the
// surface closer than a voxel or two can share vertices (non-manifold by
// position); checkTopology() counts them on the welded mesh and `sdfc mesh`
// says where and which --resolution to try (docs/mesh.md). Sharp points off
// the lattice (a cone apex on a cell edge) keep up to ~0.3 voxel of error
// because vertices stay in their cells. Regions cut by --box are left open
// there.
#pragma once
#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "eval/block_evaluator.h"
#include "ir/scene.h"

namespace sdfc {

// Largest grid accepted: 1024^3 cells in the region, plus its padding (a byte
// per sample, ~1.1 GB).
inline constexpr uint64_t kMaxMeshCells = uint64_t{1} << 30;

struct MeshOptions {
  int resolution = 128;     // cells along the longest side of the region
  double voxel_size = 0;    // > 0 overrides resolution
  std::optional<Aabb> box;  // region to mesh; required for unbounded scenes
  double time = 0;
  // One vertex per surface patch of a cell (as in Nielson's 2004 Dual
  // Marching Cubes) instead of one per cell: ambiguous cells then give
  // manifold output. false = plain DC, kept to measure the difference.
  bool split_patches = true;
  // Newton steps moving each vertex onto the surface inside its cell after
  // the QEF (0 = plain DC placement).
  int project_steps = 4;
  // Skip 8^3-sample blocks that the scene's Lipschitz bound proves empty.
  bool sparse = true;
  // Merge vertices at one point and drop what collapses (mesh_weld.h), so
  // the mesh is what a reader merging by position sees. false = as contoured.
  bool weld = true;
  int threads = 0;  // 0 = all cores
  // How the front end spells the options its messages name: the command
  // line's flags by default; the Python module gives its keywords (a Python
  // user was told to "give --box").
  struct Names {
    std::string box = "--box";
    std::string box_form = "--box x0,y0,z0,x1,y1,z1";
    std::string voxel_size = "--voxel-size";
    std::string resolution = "--resolution";
  } names;
  // (stage, fraction done); called from worker threads, serialised.
  std::function<void(const char*, double)> progress;
  const std::atomic<bool>* interrupt = nullptr;
};

// The lattice: sample (i, j, k) sits at origin + voxel * (i, j, k), for
// 0 <= i <= cells.x etc.
struct GridPlan {
  glm::dvec3 origin{0};
  double voxel = 1;
  glm::ivec3 cells{0};
  glm::ivec3 samples() const { return cells + 1; }
  uint64_t cellCount() const { return uint64_t(cells.x) * uint64_t(cells.y) * uint64_t(cells.z); }
  glm::dvec3 point(int i, int j, int k) const { return origin + voxel * glm::dvec3(i, j, k); }
};

// The grid for `scene` under `options`, or an error message (unbounded scene
// without --box, empty scene, too many cells).
struct GridPlanResult {
  GridPlan plan;
  std::string error;
};
GridPlanResult planGrid(const ir::Scene& scene, const MeshOptions& options);

// Which part of the tree makes it unbounded, e.g. "plane at line 3"; empty
// when the root's bounds are finite.
std::string describeUnbounded(const ir::Node& root);

struct SignGrid {
  GridPlan plan;
  std::vector<uint8_t> inside;  // 1 where the distance is < 0; x fastest
  uint64_t points_evaluated = 0;
  double seconds = 0;
  bool interrupted = false;
  size_t index(int i, int j, int k) const {
    const glm::ivec3 s = plan.samples();
    return size_t(i) + size_t(s.x) * (size_t(j) + size_t(s.y) * size_t(k));
  }
};
SignGrid sampleGrid(const BlockEvaluator& eval, const ir::Node& root, const GridPlan& plan,
                    const MeshOptions& options);

struct TriangleMesh {
  std::vector<glm::dvec3> positions;
  std::vector<glm::dvec3> normals;  // unit gradient of the field at each vertex
  std::vector<glm::uvec3> triangles;
  std::vector<int> materials;  // per triangle: the evaluator's material at its centroid
};

struct ContourStats {
  size_t crossing_edges = 0;
  size_t surface_cells = 0;
  size_t split_cells = 0;  // cells holding more than one vertex
  size_t clamped_vertices = 0;  // QEF minimum outside its cell
  size_t tunnel_faces = 0;  // cells whose ambiguous faces took the other pairing (see dual_contour.cpp)
  bool interrupted = false;
  double seconds = 0;
};
TriangleMesh dualContour(const BlockEvaluator& eval, const SignGrid& grid, const MeshOptions& options,
                         ContourStats* stats = nullptr);

// What weldByPosition() changed.
struct WeldStats {
  size_t merged_vertices = 0;      // folded into another vertex at the same point
  size_t collapsed_triangles = 0;  // two corners at one point: dropped
  size_t fin_triangles = 0;        // pairs on the same three corners, opposite winding: dropped
  size_t flipped_edges = 0;        // zero-area triangles with three distinct corners, repaired
  double tolerance = 0;
  double seconds = 0;
};

struct MeshResult {
  TriangleMesh mesh;
  GridPlan plan;
  std::string error;  // set: nothing was meshed
  bool interrupted = false;
  uint64_t points_evaluated = 0;
  double sample_seconds = 0;
  ContourStats contour;
  WeldStats weld;
};
// planGrid + sampleGrid + dualContour + weldByPosition.
MeshResult meshScene(const ir::Scene& scene, const MeshOptions& options);

}  // namespace sdfc
