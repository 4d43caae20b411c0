// The sampling lattice: its placement over the scene's bounds and the sign
// of the distance at every sample.
#include <chrono>
#include <cmath>
#include <mutex>
#include <sstream>

#include "mesher.h"
#include "parallel.h"

namespace sdfc {
namespace {

using glm::dvec3;

constexpr int kPadCells = 2;   // empty cells kept around the bounds
constexpr int kBlock = 8;      // samples per block side for the sparse test

const char* nodeName(const ir::Node& n) {
  switch (n.kind) {
    case ir::NodeKind::Primitive: return primitiveInfo(n.primitive).name;
    case ir::NodeKind::Union: return "union";
    case ir::NodeKind::Intersect: return "intersect";
    case ir::NodeKind::Subtract: return "subtract";
    case ir::NodeKind::Translate: return "translate";
    case ir::NodeKind::Rotate: return "rotate";
    case ir::NodeKind::Scale:
    case ir::NodeKind::ScaleNonUniform: return "scale";
    case ir::NodeKind::Affine: return "transform";
    case ir::NodeKind::Reflect: return "reflect";
    case ir::NodeKind::Repeat: return "repeat";
    case ir::NodeKind::Elongate: return "elongate";
    case ir::NodeKind::Morph: return "morph";
    case ir::NodeKind::Round: return "round";
    case ir::NodeKind::Shell: return "shell";
    case ir::NodeKind::Extrude: return "extrude";
    case ir::NodeKind::Revolve: return "revolve";
    case ir::NodeKind::Twist: return "twist";
    case ir::NodeKind::Bend: return "bend";
    case ir::NodeKind::Displace: return "displace";
    case ir::NodeKind::RepeatPolar: return "repeat_polar";
    case ir::NodeKind::Instances: return "instances";
    case ir::NodeKind::Mesh: return "mesh";
  }
  return "shape";
}

// The deepest unbounded node whose children are all bounded: the culprit.
const ir::Node* unboundedCulprit(const ir::Node& n) {
  if (n.bounds.finite()) return nullptr;
  for (const ir::NodeRef& c : n.children)
    if (const ir::Node* found = unboundedCulprit(*c)) return found;
  return &n;
}

}  // namespace

std::string describeUnbounded(const ir::Node& root) {
  const ir::Node* culprit = unboundedCulprit(root);
  if (!culprit) return "";
  std::string out = nodeName(*culprit);
  if (const int line = culprit->range.line(); line > 0) out += " at line " + std::to_string(line);
  return out;
}

GridPlanResult planGrid(const ir::Scene& scene, const MeshOptions& options) {
  GridPlanResult out;
  if (!scene.root) {
    out.error = "the file has no scene to mesh";
    return out;
  }
  Aabb region;
  int pad = kPadCells;
  if (options.box) {
    region = *options.box;
    pad = 0;  // the user's box is the region, exactly
    if (region.empty() || !region.finite() || region.lo == region.hi) {
      out.error = options.names.box + " must have x0 < x1, y0 < y1 and z0 < z1";
      return out;
    }
  } else {
    region = scene.root->bounds;
    if (region.empty()) {
      out.error = "the scene is empty (its bounds contain nothing), so there is no surface to mesh";
      return out;
    }
    if (!region.finite()) {
      out.error = "the scene is unbounded (" + describeUnbounded(*scene.root) +
                  "); give " + options.names.box_form;
      return out;
    }
  }
  const dvec3 size = region.hi - region.lo;
  const double longest = std::max(size.x, std::max(size.y, size.z));
  double voxel = options.voxel_size > 0 ? options.voxel_size
                                        : longest / std::max(1, options.resolution);
  if (!(voxel > 0) || !std::isfinite(voxel)) {
    out.error = "the scene's bounds have no extent; give " + options.names.box + " or " + options.names.voxel_size;
    return out;
  }
  // The limit counts the region's cells, not the padding around it, so every
  // --resolution up to 1024 is accepted as advertised.
  const dvec3 region_cells = glm::max(glm::ceil(size / voxel - 1e-9), dvec3(1));
  const dvec3 cells_wanted = region_cells + 2.0 * pad;
  const double total = region_cells.x * region_cells.y * region_cells.z;
  if (total > static_cast<double>(kMaxMeshCells)) {
    std::ostringstream msg;
    msg << "the grid would have " << region_cells.x << " x " << region_cells.y << " x "
        << region_cells.z << " cells, more than the limit of 1024^3; raise " << options.names.voxel_size
        << " or lower " << options.names.resolution;
    out.error = msg.str();
    return out;
  }
  out.plan.voxel = voxel;
  out.plan.cells = glm::ivec3(cells_wanted);
  // Centre the lattice on the region so rounding up spreads evenly.
  out.plan.origin = region.center() - 0.5 * voxel * dvec3(out.plan.cells);
  return out;
}

SignGrid sampleGrid(const BlockEvaluator& eval, const ir::Node& root, const GridPlan& plan,
                    const MeshOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  SignGrid grid;
  grid.plan = plan;
  const glm::ivec3 s = plan.samples();
  grid.inside.assign(size_t(s.x) * size_t(s.y) * size_t(s.z), 0);
  const glm::ivec3 blocks = (s + kBlock - 1) / kBlock;
  // |f(x) - f(c)| <= L |x - c|: a block whose centre is farther than L times
  // its half-diagonal from the surface has one sign throughout.
  const double lipschitz = std::max(root.lipschitz, 1.0);
  std::atomic<uint64_t> evaluated{0};
  std::atomic<size_t> slabs_done{0};
  std::atomic<bool> stopped{false};
  std::mutex progress_mutex;
  const size_t slab_count = size_t(blocks.z);

  std::vector<BlockEvaluator::Scratch> scratch(workerCount(options.threads));
  parallelFor(slab_count, 1, options.threads, [&](size_t begin, size_t end, int worker) {
    PointBlock points;
    BlockResult result;
    size_t where[kEvalBlock];
    auto flush = [&] {
      eval.at(points, result, scratch[worker]);
      for (int n = 0; n < points.count; ++n) grid.inside[where[n]] = result.distance[n] < 0 ? 1 : 0;
      points.count = 0;
    };
    for (size_t bz = begin; bz < end; ++bz) {
      if (options.interrupt && options.interrupt->load()) {
        stopped = true;
        return;
      }
      uint64_t local = 0;
      for (int by = 0; by < blocks.y; ++by) {
        for (int bx = 0; bx < blocks.x; ++bx) {
          const glm::ivec3 lo(bx * kBlock, by * kBlock, int(bz) * kBlock);
          const glm::ivec3 hi = glm::min(lo + kBlock, s);  // exclusive
          if (options.sparse) {
            const dvec3 c = plan.origin + plan.voxel * (dvec3(lo + hi - 1) * 0.5);
            const double radius = 0.5 * plan.voxel * glm::length(dvec3(hi - 1 - lo));
            const double d = eval.pointwise().distance(c);
            ++local;
            if (std::fabs(d) > lipschitz * radius * (1 + 1e-9) + 1e-12 * plan.voxel) {
              const uint8_t in = d < 0 ? 1 : 0;
              if (in)
                for (int k = lo.z; k < hi.z; ++k)
                  for (int j = lo.y; j < hi.y; ++j)
                    for (int i = lo.x; i < hi.x; ++i) grid.inside[grid.index(i, j, k)] = 1;
              continue;
            }
          }
          for (int k = lo.z; k < hi.z; ++k)
            for (int j = lo.y; j < hi.y; ++j)
              for (int i = lo.x; i < hi.x; ++i) {
                where[points.count] = grid.index(i, j, k);
                points.set(points.count++, plan.point(i, j, k));
                if (points.count == kEvalBlock) flush();
              }
          if (points.count) flush();
          local += uint64_t(hi.x - lo.x) * uint64_t(hi.y - lo.y) * uint64_t(hi.z - lo.z);
        }
      }
      evaluated += local;
      const size_t done = ++slabs_done;
      if (options.progress) {
        std::lock_guard<std::mutex> lock(progress_mutex);
        options.progress("sampling", double(done) / double(slab_count));
      }
    }
  });
  grid.points_evaluated = evaluated;
  grid.interrupted = stopped;
  grid.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return grid;
}

}  // namespace sdfc
