// A uniform grid over an instance set (ir::InstanceGrid): one lookup and a
// list of at most kGridListMax instances per evaluation, instead of a
// root-to-leaf descent of the hierarchy whose visits grow with log(count) and
// whose loose, overlapping boxes in dense clouds cost many sibling visits.
//
// Why the bound holds (docs/design/large_scenes.md): cell C lists every instance i
// with dist(C, box_i) < reach, and every instance left out has
// dist(C, box_i) >= reach, so box_i misses the interior of C grown by the
// ball of radius reach, and for p in C
//   dist(p, shape_i) >= dist(p, box_i) >= reach + dist(p, faces of C).
// A cell too crowded for that (reach 0) is split into octants with lists of
// their own (sub-cells, half the size and reach); only an octant still
// crowded leaves its points to the hierarchy.
// Outside the grid's box G = bounds grown by `margin` on every side,
// dist(p, bounds) >= dist(p, G) + margin (per axis the excess over the bounds
// is the excess over G plus margin; the sum of squares only grows).
#include <algorithm>
#include <cmath>

#include "passes/passes.h"

namespace sdfc {
namespace {

using glm::dvec3;

// Cells per instance (about one instance per cell keeps lists short) and the
// reach a cell aims for, in cells: larger steps in empty space against longer
// lists.
constexpr double kGridCellsPerInstance = 1.0;
constexpr double kReachInCells = 0.5;
// A sphere cloud's cells become fixed slots in the shader's data (96 bytes a
// cell, glsl_emitter.cpp). At most this many cells keep a million spheres'
// data (122 MB with their records and hierarchy) within the 128 MiB storage
// buffer range every Vulkan device has; there a cell holds 1.3 spheres.
constexpr double kMaxSphereCloudCells = 800000;

// Distance from a ball of radius r centred at c to a box, 0 where they touch.
double ballBoxDistance(const Aabb& box, const dvec3& c, double r) {
  return std::max(box.distance(c) - r, 0.0);
}

}  // namespace

void buildInstanceGrid(ir::InstanceSet& set, const ir::Node& node) {
  const ir::Node& templ = *node.children[0];  // the point cloud's sphere, when it is one
  ir::InstanceGrid& g = set.grid;
  g = ir::InstanceGrid{};
  const size_t n = set.size();
  if (n == 0) return;
  std::vector<Aabb> boxes(n);
  std::vector<double> sizes(n);
  Aabb bounds;
  for (size_t i = 0; i < n; ++i) {
    boxes[i] = instanceBounds(set, i, node);
    if (!boxes[i].finite()) return;
    bounds = bounds.unite(boxes[i]);
    const dvec3 e = boxes[i].hi - boxes[i].lo;
    sizes[i] = std::max({e.x, e.y, e.z});
  }
  std::nth_element(sizes.begin(), sizes.begin() + n / 2, sizes.end());
  const double typical = std::max(sizes[n / 2], 1e-9);
  // Cubic cells, about kGridCellsPerInstance per instance over the bounds (each
  // axis counted at least one typical instance wide), never smaller than a
  // typical instance.
  const dvec3 extent = glm::max(bounds.hi - bounds.lo, dvec3(typical));
  double max_cells = std::min<double>(4.0 * double(n) + 4096, double(ir::kGridMaxEntry));
  if (ir::isSphereCloud(set, templ)) max_cells = std::min(max_cells, kMaxSphereCloudCells);
  double cell =
      std::max(std::cbrt(extent.x * extent.y * extent.z / std::min(kGridCellsPerInstance * double(n), max_cells)), typical);
  // A bound the grid gives (a reach, the margin) must exceed what the nodes
  // above may take off it (ir::Node::lowered: a round's radius above the
  // set), or the field would cross 0 in empty space: every reach is more
  // than `reach_floor` (1% above, as the march confirms a hit within float
  // error of 0), a cell that cannot have one being crowded; the reaches
  // aimed for are above that.
  const double reach_floor = 1.01 * node.lowered, floor_target = 1.02 * node.lowered;
  glm::dvec3 dims;
  for (;;) {
    g.margin = std::max(kReachInCells * cell, floor_target);
    dims = glm::ceil((bounds.hi - bounds.lo + 2.0 * g.margin) / cell);
    if (dims.x * dims.y * dims.z <= max_cells) break;
    cell *= 1.05;
  }
  g.cell = cell;
  g.dims = glm::ivec3(dims);
  g.lo = bounds.lo - g.margin;
  const double reach = g.margin;
  const size_t cells = size_t(g.dims.x) * g.dims.y * g.dims.z;

  // Candidates: instances whose box grown by `reach` (a box, so a superset of
  // the ball) overlaps the cell, counted then filled (one array, no per-cell
  // vectors: a million cells).
  auto cellRange = [&](const Aabb& b, glm::ivec3& c0, glm::ivec3& c1) {
    c0 = glm::clamp(glm::ivec3(glm::floor((b.lo - reach - g.lo) / cell)), glm::ivec3(0), g.dims - 1);
    c1 = glm::clamp(glm::ivec3(glm::floor((b.hi + reach - g.lo) / cell)), glm::ivec3(0), g.dims - 1);
  };
  auto cellIndex = [&](int x, int y, int z) { return size_t(x) + size_t(g.dims.x) * (size_t(y) + size_t(g.dims.y) * z); };
  std::vector<std::uint32_t> cand_first(cells + 1, 0);
  size_t total = 0;
  for (size_t i = 0; i < n; ++i) {
    glm::ivec3 c0, c1;
    cellRange(boxes[i], c0, c1);
    const size_t touched = size_t(c1.x - c0.x + 1) * (c1.y - c0.y + 1) * (c1.z - c0.z + 1);
    total += touched;
    // A few huge instances over a fine grid: not worth the memory.
    if (total > 64 * n + (size_t(1) << 20)) return;
    for (int z = c0.z; z <= c1.z; ++z)
      for (int y = c0.y; y <= c1.y; ++y)
        for (int x = c0.x; x <= c1.x; ++x) cand_first[cellIndex(x, y, z) + 1]++;
  }
  for (size_t c = 0; c < cells; ++c) cand_first[c + 1] += cand_first[c];
  std::vector<std::uint32_t> cand(total), fill(cand_first.begin(), cand_first.end() - 1);
  for (size_t i = 0; i < n; ++i) {
    glm::ivec3 c0, c1;
    cellRange(boxes[i], c0, c1);
    for (int z = c0.z; z <= c1.z; ++z)
      for (int y = c0.y; y <= c1.y; ++y)
        for (int x = c0.x; x <= c1.x; ++x) cand[fill[cellIndex(x, y, z)]++] = std::uint32_t(i);
  }
  fill = {};

  g.first.resize(cells);
  g.count.resize(cells);
  g.reach.resize(cells);
  std::vector<std::pair<double, std::uint32_t>> near;
  // A point cloud's spheres are ranked by their own distance to the cell,
  // dist(C, centre) - r (0 if it touches), not their boxes': the argument
  // above needs only dist(C, shape_i) >= reach, and a ball is nearer its box's
  // corners than it. Fewer spheres touch a cell (fewer crowded cells) and
  // reaches are longer.
  const double sphere_r = ir::isSphereCloud(set, templ) ? templ.args[0].value : 0;
  // An octant still crowded at kGridListMax lists up to kGridListMaxCrowded
  // (a sphere cloud's slots hold kGridListMax): a longer loop costs far less
  // than the hierarchy's search (a 10,000-part tree: 654 -> 265 CPU ms a
  // sample; at 64, 298; other families unchanged or faster; bench/results/many_parts.md).
  const size_t crowded_max = sphere_r > 0 ? size_t(ir::kGridListMax) : size_t(ir::kGridListMaxCrowded);
  // Cell c (main or sub-cell) with box `box` lists the nearest of the main
  // cell `from`'s candidates within `target`.
  // `octant`: a sub-cell, the last level, which may take the longer list.
  auto listCell = [&](size_t c, const Aabb& box, size_t from, double target, bool octant) {
    near.clear();
    for (std::uint32_t k = cand_first[from]; k < cand_first[from + 1]; ++k) {
      // A cloud's instance at offset o is the sphere centred at -o.
      const double d = sphere_r > 0 ? ballBoxDistance(box, -set.instances[cand[k]].offset, sphere_r)
                                    : box.distance(boxes[cand[k]]);
      if (d < target) near.push_back({d, cand[k]});
    }
    std::sort(near.begin(), near.end());
    if (sphere_r > 0) {
      // Copies of one sphere (a point listed twice in a file) are one
      // surface: list it once, or 9 copies would crowd every cell near them.
      // A copy has its twin's distance, so it sorts beside it.
      size_t kept = 0;
      for (size_t k = 0; k < near.size(); ++k) {
        const ir::Instance& a = set.instances[near[k].second];
        bool copy = false;
        for (size_t j = kept; j-- > 0 && near[j].first == near[k].first;) {
          const ir::Instance& b = set.instances[near[j].second];
          copy = copy || (a.offset == b.offset && a.material == b.material);
        }
        if (!copy) near[kept++] = near[k];
      }
      near.resize(kept);
    }
    double r = target;
    size_t keep = near.size();
    for (size_t list_max : {size_t(ir::kGridListMax), octant ? crowded_max : size_t(ir::kGridListMax)}) {
      r = target;
      keep = near.size();
      if (keep > list_max) {
        // The nearest list_max; the rest are at least as far as the first left out.
        r = near[list_max].first;
        keep = list_max;
        while (keep > 0 && near[keep - 1].first >= r) --keep;
      }
      if (r > reach_floor) break;
    }
    g.first[c] = static_cast<std::uint32_t>(g.entries.size());
    g.reach[c] = r;
    // More than kGridListMax boxes touch the cell: its reach is 0 and the
    // steps in it would never leave it. (A small reach only makes small
    // steps: still right, unlike a hierarchy that runs out of visits and
    // returns a box distance.)
    if (!(r > reach_floor)) {
      g.count[c] = ir::kGridCrowded;
      return;
    }
    g.count[c] = static_cast<std::int32_t>(keep);
    for (size_t k = 0; k < keep; ++k) g.entries.push_back(near[k].second);
  };
  for (int z = 0; z < g.dims.z; ++z)
    for (int y = 0; y < g.dims.y; ++y)
      for (int x = 0; x < g.dims.x; ++x) {
        const size_t c = cellIndex(x, y, z);
        const dvec3 lo = g.lo + dvec3(x, y, z) * cell;
        listCell(c, Aabb{lo, lo + cell}, c, reach, false);
      }
  // A crowded cell is split once into its 8 octants, each with its own list
  // and half the reach (a sub-cell's candidates are among its cell's: what
  // lies within reach / 2 of the octant lies within reach of the cell). An
  // octant still crowded takes a longer list; only one crowded even then
  // leaves its points to the hierarchy: a dense clump costs one more lookup
  // and a longer loop, not a traversal.
  const double half = 0.5 * cell;
  for (int z = 0; z < g.dims.z; ++z)
    for (int y = 0; y < g.dims.y; ++y)
      for (int x = 0; x < g.dims.x; ++x) {
        const size_t c = cellIndex(x, y, z);
        if (g.count[c] != ir::kGridCrowded) continue;
        const size_t sub = g.count.size();
        g.first[c] = static_cast<std::uint32_t>(sub);
        g.count[c] = ir::kGridSplit;
        g.reach[c] = 0;
        g.first.resize(sub + 8);
        g.count.resize(sub + 8);
        g.reach.resize(sub + 8);
        const dvec3 lo = g.lo + dvec3(x, y, z) * cell;
        for (int o = 0; o < 8; ++o) {
          const dvec3 sub_lo = lo + dvec3(o & 1, (o >> 1) & 1, (o >> 2) & 1) * half;
          listCell(sub + size_t(o), Aabb{sub_lo, sub_lo + half}, c,
                   std::max(kReachInCells * half, std::min(reach, floor_target)), true);
        }
      }
  if (g.entries.size() > ir::kGridMaxEntry) g = ir::InstanceGrid{};
}

ir::GridCellAt instanceGridCellAt(const ir::InstanceGrid& g, const glm::dvec3& p) {
  const dvec3 f = (p - g.lo) / g.cell;
  const glm::ivec3 c = glm::clamp(glm::ivec3(glm::floor(f)), glm::ivec3(0), g.dims - 1);
  ir::GridCellAt at;
  at.index = size_t(c.x) + size_t(g.dims.x) * (size_t(c.y) + size_t(g.dims.y) * c.z);
  at.q = f - dvec3(c);
  at.size = g.cell;
  while (g.count[at.index] == ir::kGridSplit) {
    const glm::ivec3 o(glm::greaterThanEqual(at.q, dvec3(0.5)));
    at.index = g.first[at.index] + size_t(o.x + 2 * o.y + 4 * o.z);
    at.q = at.q * 2.0 - dvec3(o);
    at.size *= 0.5;
  }
  return at;
}

double instanceGridBound(const ir::InstanceSet& set, const glm::dvec3& p,
                         const std::function<double(size_t)>& distance_of) {
  const ir::InstanceGrid& g = set.grid;
  const dvec3 hi = g.lo + dvec3(g.dims) * g.cell;
  const dvec3 outside = glm::max(glm::max(g.lo - p, p - hi), dvec3(0));
  if (outside != dvec3(0)) return glm::length(outside) + g.margin;
  const ir::GridCellAt at = instanceGridCellAt(g, p);
  if (g.count[at.index] < 0) return std::nan("");
  const dvec3 in = glm::min(at.q, 1.0 - at.q);
  double best = g.reach[at.index] + at.size * std::max(0.0, std::min({in.x, in.y, in.z}));
  for (std::int32_t k = 0; k < g.count[at.index]; ++k)
    best = std::min(best, distance_of(g.entries[g.first[at.index] + k]));
  return best;
}

// Along a ray from p in a listed cell C the same argument holds for every
// point of the ray up to C's exit plus the reach: such a point lies in C or
// within the reach of it, where no unlisted box is. So nothing unlisted is
// met before t_exit + reach, and the first listed hit bounds the rest.
double instanceGridRaySkip(const ir::InstanceSet& set, const glm::dvec3& p, const glm::dvec3& dir,
                           const std::function<double(size_t)>& hit_of) {
  const ir::InstanceGrid& g = set.grid;
  const dvec3 hi = g.lo + dvec3(g.dims) * g.cell;
  if (glm::any(glm::lessThan(p, g.lo)) || glm::any(glm::greaterThan(p, hi))) return 0;
  const ir::GridCellAt at = instanceGridCellAt(g, p);
  if (g.count[at.index] < 0) return 0;
  double exit = 1e300;
  for (int a = 0; a < 3; ++a)
    if (dir[a] != 0) exit = std::min(exit, (dir[a] > 0 ? 1 - at.q[a] : at.q[a]) / std::fabs(dir[a]));
  double skip = g.reach[at.index] + at.size * std::max(exit, 0.0);
  for (std::int32_t k = 0; k < g.count[at.index]; ++k)
    skip = std::min(skip, hit_of(g.entries[g.first[at.index] + k]));
  return skip;
}

}  // namespace sdfc
