#include "mesher.h"

#include <chrono>

#include "mesh_weld.h"

namespace sdfc {

MeshResult meshScene(const ir::Scene& scene, const MeshOptions& options) {
  MeshResult out;
  GridPlanResult planned = planGrid(scene, options);
  if (!planned.error.empty()) {
    out.error = planned.error;
    return out;
  }
  out.plan = planned.plan;
  // Each sample evaluates the parts its cell lists (the same bits, faster on many parts).
  const BlockEvaluator eval(scene, options.time, true);
  const SignGrid grid = sampleGrid(eval, *scene.root, out.plan, options);
  out.points_evaluated = grid.points_evaluated;
  out.sample_seconds = grid.seconds;
  if (grid.interrupted) {
    out.interrupted = true;
    return out;
  }
  out.mesh = dualContour(eval, grid, options, &out.contour);
  out.interrupted = out.contour.interrupted;
  if (!out.interrupted && options.weld) {
    const auto start = std::chrono::steady_clock::now();
    const double tolerance = weldTolerance(out.mesh, out.plan.voxel);
    out.weld = weldByPosition(out.mesh, tolerance);
    out.weld.tolerance = tolerance;
    out.weld.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  return out;
}

}  // namespace sdfc
