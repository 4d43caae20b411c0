// `sdfc mesh`: the scene's surface as a triangle mesh (.glb, .gltf, .stl),
// by dual contouring on a grid sampled with the float64 evaluator (mesh/).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>
#include <unistd.h>

#include "cli_support.h"
#include "commands.h"
#include "mesh_quality.h"
#include "mesh_write.h"
#include "mesher.h"
#include "runtime/progress.h"

namespace sdfc {
namespace {

// "x0,y0,z0,x1,y1,z1" -> box; nullopt when malformed.
std::optional<Aabb> parseBox(const std::string& text) {
  std::istringstream in(text);
  double v[6];
  for (int i = 0; i < 6; ++i) {
    if (!(in >> v[i])) return std::nullopt;
    char comma = 0;
    if (i < 5 && (!(in >> comma) || comma != ',')) return std::nullopt;
  }
  std::string rest;
  if (in >> rest) return std::nullopt;
  Aabb box{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}};
  if (!(box.lo.x < box.hi.x && box.lo.y < box.hi.y && box.lo.z < box.hi.z)) return std::nullopt;
  return box;
}

// Progress per stage on stderr: redrawn in place on a terminal; in a log,
// a line at most every few seconds (a short mesh prints none), as `render`
// rate-limits its lines.
std::function<void(const char*, double)> makeMeshProgress() {
  constexpr double kLogInterval = 3.0;
  const bool tty = isatty(STDERR_FILENO);
  struct State {
    std::string stage;
    int shown = -1;
    std::chrono::steady_clock::time_point last_line = std::chrono::steady_clock::now();
  };
  auto state = std::make_shared<State>();
  return [tty, state](const char* stage, double fraction) {
    const int percent = int(fraction * 100);
    if (state->stage != stage) state->stage = stage, state->shown = -1;
    if (percent <= state->shown) return;  // workers may report out of order
    if (tty) {
      state->shown = percent;
      std::fprintf(stderr, "\rsdfc: %-10s %3d%%%s", stage, percent, percent == 100 ? "\n" : "");
    } else {
      const auto now = std::chrono::steady_clock::now();
      if (std::chrono::duration<double>(now - state->last_line).count() < kLogInterval) return;
      state->shown = percent;
      state->last_line = now;
      std::fprintf(stderr, "sdfc: %s %d%%\n", stage, percent);
    }
    std::fflush(stderr);
  };
}

}  // namespace

int runMesh(const CommandLine& cl) {
  const std::optional<MeshFormat> format = meshFormatFor(cl.output);
  if (!format) {
    std::cerr << "sdfc: error: mesh output must end in .glb, .gltf or .stl, got '" << cl.output << "'\n";
    return kExitUsage;
  }
  MeshOptions options;
  options.resolution = cl.resolution;
  options.voxel_size = cl.voxel_size;
  options.time = cl.time;
  if (!checkTimeOption(cl.time)) return kExitUsage;
  if (cl.voxel_size < 0) {
    std::cerr << "sdfc: error: --voxel-size must be positive\n";
    return kExitUsage;
  }
  if (!cl.box.empty()) {
    options.box = parseBox(cl.box);
    if (!options.box) {
      std::cerr << "sdfc: error: --box expects x0,y0,z0,x1,y1,z1 with x0 < x1, y0 < y1, z0 < z1, got '"
                << cl.box << "'\n";
      return kExitUsage;
    }
  }
  checkWritablePath(cl.output);  // before the work, not after
  Diagnostics diags;
  LoadedScene loaded = loadScene(cl, diags, /*emit=*/false);
  if (loaded.exit_code != kExitOk) return loaded.exit_code;
  const ir::Scene& scene = loaded.compiled.scene;
  if (!cl.quiet) options.progress = makeMeshProgress();
  options.interrupt = installInterruptHandler();

  MeshResult result = meshScene(scene, options);
  if (!result.error.empty()) {
    std::cerr << "sdfc: error: " << result.error << "\n";
    return kExitUsage;
  }
  if (result.interrupted) {
    std::cerr << "sdfc: interrupted; no mesh written\n";
    return kExitInterrupted;
  }
  const TriangleMesh& mesh = result.mesh;
  const auto finish_start = std::chrono::steady_clock::now();
  try {
    writeFileAtomically(cl.output, encodeMesh(mesh, scene, *format, cl.time));
  } catch (const std::exception& e) {
    std::cerr << "sdfc: error: " << e.what() << "\n";
    return kExitIo;
  }
  const double write_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - finish_start).count();

  const Evaluator eval(scene, cl.time);
  const double error = maxVertexError(eval, mesh);
  const MeshTopology topo = checkTopology(mesh);
  const GridPlan& plan = result.plan;
  std::printf("sdfc: wrote %s\n", cl.output.c_str());
  std::printf("  grid: %d x %d x %d cells, voxel %.6g\n", plan.cells.x, plan.cells.y, plan.cells.z, plan.voxel);
  std::printf("  triangles: %zu, vertices: %zu\n", mesh.triangles.size(), mesh.positions.size());
  std::printf("  max vertex |distance|: %.3g voxel (%.3g)\n", error / plan.voxel, error);
  const WeldStats& weld = result.weld;
  if (weld.merged_vertices)
    std::printf("  welded: %zu vertices at the point of another (merged), %zu triangles collapsed, "
                "%zu fins and %zu zero-area triangles repaired\n",
                weld.merged_vertices, weld.collapsed_triangles, weld.fin_triangles, weld.flipped_edges);
  // By position, as a slicer reads the file: meshScene welded it.
  if (topo.closedManifold() && topo.degenerate_triangles == 0) {
    std::printf("  topology: closed manifold, consistent winding, Euler characteristic %ld\n", topo.euler);
  } else {
    std::printf("  topology: not a closed manifold: %zu boundary edges, %zu edges used by more than two "
                "triangles, %zu non-manifold vertices, %zu inconsistently wound edges, %zu zero-area "
                "triangles\n",
                topo.boundary_edges, topo.non_manifold_edges, topo.non_manifold_vertices,
                topo.inconsistent_edges, topo.degenerate_triangles);
    // To a thousandth of a voxel, so 0 prints as 0 rather than 5.7e-15.
    const double grain = 1e-3 * plan.voxel;
    const glm::dvec3 at = glm::round(topo.problem_at.value_or(glm::dvec3(0)) / grain) * grain + 0.0;
    if (topo.non_manifold_edges || topo.non_manifold_vertices || topo.degenerate_triangles) {
      char finer[64];
      if (cl.voxel_size > 0)
        std::snprintf(finer, sizeof finer, "--voxel-size %.3g", plan.voxel / 2);
      else
        std::snprintf(finer, sizeof finer, "--resolution %d", 2 * cl.resolution);
      std::printf("  note: near (%.4g, %.4g, %.4g) parts of the surface come within a voxel or two (%.3g) "
                  "of each other (a thin wall, a narrow gap or hole), so a slicer sees them touch; a finer "
                  "grid separates them (%s), unless they touch in the scene itself\n",
                  at.x, at.y, at.z, plan.voxel, finer);
    } else if (topo.boundary_edges) {
      std::printf("  note: open where the surface leaves the grid (near (%.4g, %.4g, %.4g))%s\n", at.x,
                  at.y, at.z, options.box ? ", cut by --box" : "");
    }
  }
  if (topo.boundary_edges == 0) std::printf("  volume: %.6g\n", meshVolume(mesh));
  const double rate = result.sample_seconds > 0 ? result.points_evaluated / result.sample_seconds : 0;
  std::printf("  time: sampling %s (%llu points, %.3g M points/s), contouring %s, welding %s, writing %s\n",
              formatSeconds(result.sample_seconds).c_str(),
              static_cast<unsigned long long>(result.points_evaluated), rate / 1e6,
              formatSeconds(result.contour.seconds).c_str(), formatSeconds(result.weld.seconds).c_str(),
              formatSeconds(write_seconds).c_str());
  return kExitOk;
}

}  // namespace sdfc
