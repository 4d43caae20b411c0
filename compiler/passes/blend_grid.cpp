// A smooth set's grid (ir::InstanceGrid with `blend`): per cell, the members
// that can change the blend there, so a point folds a short list instead of
// visiting the hierarchy. Lipschitz pruning (Barbier et al., Eurographics
// 2025) for an n-ary blend.
//
// A set's blend is the chain of polynomial smooth minima taken in the order
// of the members' values at the point, nearest first:
//   F = smin(...smin(smin(x_(1), x_(2), k), x_(3), k)..., x_(n), k).
// It does not depend on how the members are listed, it is continuous (where
// two values cross, the two orders give the same result), and F <= x_(1) = m
// after the first, so a member with x >= m + k changes nothing
// (smin(a, b, k) = min(a, b) exactly where |a - b| >= k): only the members
// within k of the nearest count, and F >= m - 1.25 k
// (docs/design/large_scenes.md).
// Over a cell C each member's value lies in [lo_j, hi_j] (its value at the
// centre c +- L_j h, h the half diagonal, L_j its Lipschitz constant; lo_j at
// least its box's distance from C too, where that is not 0). With U = min hi_j, a member with
// lo_j >= U + k is never within k of the nearest in C: the cell lists the
// others, and the blend of its list is the set's blend, bit for bit, wherever
// the margin for float32 rounding holds.
#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>

#include "passes/passes.h"

namespace sdfc {
namespace {

using glm::dvec3;

// Cells per instance, and the list length above which a cell is split into
// octants (half the interval width): 4 and 8 took the least CPU time on
// 1,000-part molecules and kit-bashes among 1-16 and 4-16.
constexpr double kCellsPerInstance = 4.0;
constexpr size_t kSplitAbove = 8;
// Cell-centre evaluations a build may spend: per member and in all. A
// 10,000-sphere molecule spends 450 per member, a kit-bash 470, a 1,000-twig
// tree 2,600 (2.6 million); a 10,000-twig tree, whose crown holds more than
// 128 twigs within k of a point, spent 4,600 per member (3.2 s) before
// failing.
constexpr size_t kEvaluationsPerMember = 1000;
constexpr size_t kEvaluationsAtLeast = 2000000;
// An octant is split again only for a list this long (a clump of parts
// meeting in one place): more levels cost a lookup each.
constexpr size_t kSplitAgainAbove = 32;
// The kernel keeps a list's values in an array this long at most: a longer
// list (a blend radius spanning many members) leaves the set to its hierarchy.
constexpr size_t kMaxList = 128;
// Beyond this many members within reach of one cell the set keeps its
// hierarchy alone (a blend radius comparable with the whole set).
constexpr size_t kMaxCandidates = 4096;
constexpr size_t kMaxIndex = (size_t(1) << 24) - 1;

double gapSquared(const Aabb& a, const Aabb& b) {
  const dvec3 gap = glm::max(glm::max(a.lo - b.hi, b.lo - a.hi), dvec3(0));
  return glm::dot(gap, gap);
}

double boxBoxDistance(const Aabb& a, const Aabb& b) { return std::sqrt(gapSquared(a, b)); }

struct Interval {
  double lo, hi;
};

class BlendGridBuilder {
 public:
  BlendGridBuilder(ir::InstanceSet& set, const ir::Node& node, double k,
                   const std::function<double(size_t, const dvec3&)>& distance_of,
                   const std::vector<double>& lipschitz, const std::vector<bool>& exact)
      : set_(set), node_(node), k_(k), distance_of_(distance_of), lipschitz_(lipschitz), exact_(exact),
        all_exact_(std::find(exact.begin(), exact.end(), false) == exact.end()) {}

  bool build() {
    ir::InstanceGrid& g = set_.grid;
    g = ir::InstanceGrid{};
    const size_t n = set_.size();
    if (n == 0 || set_.nodes.empty()) return false;
    boxes_.resize(n);
    std::vector<double> sizes(n);
    Aabb bounds;
    for (size_t i = 0; i < n; ++i) {
      boxes_[i] = instanceBounds(set_, i, node_);
      if (!boxes_[i].finite()) return false;
      bounds = bounds.unite(boxes_[i]);
      const dvec3 e = boxes_[i].hi - boxes_[i].lo;
      sizes[i] = std::max({e.x, e.y, e.z});
    }
    std::nth_element(sizes.begin(), sizes.begin() + n / 2, sizes.end());
    const double typical = std::max(sizes[n / 2], 1e-9);
    const dvec3 extent = glm::max(bounds.hi - bounds.lo, dvec3(typical));
    const double max_cells = std::min<double>(kCellsPerInstance * double(n) + 4096, double(kMaxIndex));
    double cell = std::max(std::cbrt(extent.x * extent.y * extent.z / (kCellsPerInstance * double(n))), 0.5 * typical);
    // The box is the bounds grown by 1.25 k plus half a cell: outside it every
    // member is that far, the blend at least half a cell (a positive bound).
    dvec3 dims;
    for (;;) {
      pad_ = 1.25 * k_ + 0.5 * cell;
      dims = glm::ceil((bounds.hi - bounds.lo + 2.0 * pad_) / cell);
      if (dims.x * dims.y * dims.z <= max_cells) break;
      cell *= 1.05;
    }
    g.cell = cell;
    g.dims = glm::ivec3(dims);
    g.lo = bounds.lo - pad_;
    g.margin = pad_ - 1.25 * k_;
    g.blend = true;
    budget_ = kEvaluationsPerMember * n + kEvaluationsAtLeast;
    // float32 rounding of the kernel's values (coordinates up to `scale`)
    // must not turn a proven drop or reset into a near miss.
    const dvec3 hi = g.lo + dims * cell;
    const double scale = std::max(glm::length(glm::max(glm::abs(g.lo), glm::abs(hi))), glm::length(extent));
    slack_ = 1e-3 * k_ + 1e-5 * scale;

    const size_t cells = size_t(g.dims.x) * g.dims.y * g.dims.z;
    g.first.resize(cells);
    g.count.resize(cells);
    g.reach.assign(cells, 0);
    for (int z = 0; z < g.dims.z; ++z)
      for (int y = 0; y < g.dims.y; ++y)
        for (int x = 0; x < g.dims.x; ++x) {
          const size_t c = size_t(x) + size_t(g.dims.x) * (size_t(y) + size_t(g.dims.y) * z);
          const dvec3 lo = g.lo + dvec3(x, y, z) * cell;
          if (far(Aabb{lo, lo + cell}, c)) continue;
          if (!cellList(Aabb{lo, lo + cell}, c, 0)) return fail();
          if (g.entries.size() > kMaxIndex) return fail();
        }
    return true;
  }

 private:
  bool fail() {
    set_.grid = ir::InstanceGrid{};
    return false;
  }

  void store(size_t c) {
    ir::InstanceGrid& g = set_.grid;
    g.longest = std::max(g.longest, static_cast<int>(list_.size()));
    g.first[c] = static_cast<std::uint32_t>(g.entries.size());
    g.count[c] = static_cast<std::int32_t>(list_.size());
    for (std::uint32_t i : list_) g.entries.push_back(i);
  }

  // Members whose boxes lie within r of `box`: from the hierarchy, or
  // (`within`) from a list that holds every member within r of it.
  void near(const Aabb& box, double r, std::vector<std::uint32_t>& out,
            const std::vector<std::uint32_t>* within = nullptr) {
    out.clear();
    const double rr = r * r;
    if (within) {
      for (std::uint32_t i : *within)
        if (gapSquared(boxes_[i], box) < rr) out.push_back(i);
      return;
    }
    stack_.assign(1, 0);
    while (!stack_.empty()) {
      const std::uint32_t ni = stack_.back();
      stack_.pop_back();
      const ir::BvhNode& node = set_.nodes[ni];
      if (gapSquared(node.box, box) >= rr) continue;
      if (node.count == 0) {
        stack_.push_back(ni + 1);
        stack_.push_back(node.first);
        continue;
      }
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i)
        if (gapSquared(boxes_[i], box) < rr) out.push_back(i);
    }
  }

  // The members that can come within k of the nearest in `box`: all with
  // a lower bound under U + k. Members whose boxes lie farther than r are
  // not evaluated, so r must reach U + k.
  // Cell c's list, or (longer than kSplitAbove, above the deepest level)
  // eight octants with lists of their own. An octant's candidates come from
  // its cell's (every member within the cell's reach).
  bool cellList(const Aabb& box, size_t c, int level) {
    if (!list(box, list_, level > 0 ? &parents_[level - 1] : nullptr, level > 0 ? parent_r_[level - 1] : 0))
      return false;
    if (list_.size() <= (level == 0 ? kSplitAbove : kSplitAgainAbove) || level == ir::kGridMaxSplits) {
      if (list_.size() > kMaxList) return false;
      store(c);
      return true;
    }
    ir::InstanceGrid& g = set_.grid;
    g.splits = std::max(g.splits, level + 1);
    const size_t sub = g.count.size();
    g.first[c] = static_cast<std::uint32_t>(sub);
    g.count[c] = ir::kGridSplit;
    g.first.resize(sub + 8);
    g.count.resize(sub + 8);
    g.reach.resize(sub + 8, 0);
    if (parents_.size() <= size_t(level)) {
      parents_.resize(level + 1);
      parent_r_.resize(level + 1);
    }
    parents_[level] = candidates_;
    parent_r_[level] = reach_;
    const dvec3 half = 0.5 * (box.hi - box.lo);
    for (int o = 0; o < 8; ++o) {
      const dvec3 sub_lo = box.lo + dvec3(o & 1, (o >> 1) & 1, (o >> 2) & 1) * half;
      if (!cellList(Aabb{sub_lo, sub_lo + half}, sub + size_t(o), level + 1)) return false;
    }
    return true;
  }

  // A cell far from every member (of a set of exact members) lists none: its
  // members' boxes are at least g from it, the nearest box's gap, so for p in
  // it every member is at least g + (p's distance to its faces) away (the
  // hard grid's argument, instance_grid.cpp) and the blend at least that
  // less 1.25 k. Where that is at least the cell's half diagonal the kernel
  // steps on it (a march never stops there); the evaluator searches all
  // members. A list there would hold the many members facing the cell.
  bool far(const Aabb& box, size_t c) {
    if (!all_exact_) return false;
    nearest(box, 1, candidates_);
    const double g = boxBoxDistance(boxes_[candidates_[0]], box);
    if (g - 1.25 * k_ < 0.5 * glm::length(box.hi - box.lo)) return false;
    ir::InstanceGrid& grid = set_.grid;
    grid.first[c] = static_cast<std::uint32_t>(grid.entries.size());
    grid.count[c] = 0;
    grid.reach[c] = g - 1.25 * k_;
    return true;
  }

  // The `count` members whose boxes are nearest `box`, best first.
  void nearest(const Aabb& box, size_t count, std::vector<std::uint32_t>& out) {
    out.clear();
    using Entry = std::pair<double, std::int64_t>;  // gap squared; node index, or -1 - member
    std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> queue;
    queue.push({gapSquared(set_.nodes[0].box, box), 0});
    while (!queue.empty() && out.size() < count) {
      const auto [gap, id] = queue.top();
      queue.pop();
      if (id < 0) {
        out.push_back(static_cast<std::uint32_t>(-1 - id));
        continue;
      }
      const ir::BvhNode& node = set_.nodes[size_t(id)];
      if (node.count == 0) {
        queue.push({gapSquared(set_.nodes[size_t(id) + 1].box, box), id + 1});
        queue.push({gapSquared(set_.nodes[node.first].box, box), node.first});
        continue;
      }
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i)
        queue.push({gapSquared(boxes_[i], box), -1 - std::int64_t(i)});
    }
  }

  // An octant's candidates come from its cell's (`parent`, every member
  // within `parent_r` of the cell): the octant needs no more than that, as
  // its least upper value is at most the cell's.
  bool list(const Aabb& box, std::vector<std::uint32_t>& out, const std::vector<std::uint32_t>* parent = nullptr,
            double parent_r = 0) {
    const dvec3 c = box.center();
    const double h = 0.5 * glm::length(box.hi - box.lo);
    // A first reach from the members of the nearest few boxes: the least of
    // their upper values plus k (found best first, so a cell far from the
    // parts does not gather the many between).
    double r = 2 * h + k_;
    if (!parent) {
      nearest(box, 8, candidates_);
      double least = std::numeric_limits<double>::infinity();
      evaluations_ += candidates_.size();
      for (std::uint32_t i : candidates_) least = std::min(least, distance_of_(i, c) + lipschitz_[set_.instances[i].templ] * h);
      r = least + k_ + slack_;
    }
    for (;;) {
      near(box, r, candidates_, parent && r <= parent_r ? parent : nullptr);
      if (candidates_.size() > kMaxCandidates) return false;
      if (candidates_.empty()) {
        r *= 2;
        continue;
      }
      evaluations_ += candidates_.size();
      if (evaluations_ > budget_) return false;
      values_.resize(candidates_.size());
      double least_hi = std::numeric_limits<double>::infinity();
      for (size_t j = 0; j < candidates_.size(); ++j) {
        const std::uint32_t i = candidates_[j];
        const double v = distance_of_(i, c), spread = lipschitz_[set_.instances[i].templ] * h;
        // A cell apart from an exact member's box: the member is at least that
        // far (a box touching the cell bounds nothing: the member may be
        // inside; a bound's value may lie below its box's distance).
        const double apart = exact_[set_.instances[i].templ] ? boxBoxDistance(boxes_[i], box) : 0;
        values_[j] = {apart > 0 ? std::max(v - spread, apart) : v - spread, v + spread};
        least_hi = std::min(least_hi, values_[j].hi);
      }
      const double cut = least_hi + k_ + slack_;
      if (r < cut) {
        r = cut;
        continue;
      }
      out.clear();
      for (size_t j = 0; j < candidates_.size(); ++j)
        if (values_[j].lo < cut) out.push_back(candidates_[j]);
      reach_ = r;
      // Kind-major, then leaf order (neighbouring records): a mixed set's
      // entry branches on its template, and lanes in lockstep on neighbouring
      // cells then tend to take the same branch at the same place in their
      // lists (docs/design/large_scenes.md, "Cost per part").
      std::sort(out.begin(), out.end(), [&](std::uint32_t a, std::uint32_t b) {
        const std::int32_t ta = set_.instances[a].templ, tb = set_.instances[b].templ;
        return ta != tb ? ta < tb : a < b;
      });
      return true;
    }
  }

  ir::InstanceSet& set_;
  const ir::Node& node_;
  double k_;
  const std::function<double(size_t, const dvec3&)>& distance_of_;
  const std::vector<double>& lipschitz_;
  const std::vector<bool>& exact_;
  bool all_exact_;
  std::vector<Aabb> boxes_;
  double pad_ = 0, slack_ = 0;
  std::vector<std::uint32_t> candidates_, list_, stack_;
  std::vector<std::vector<std::uint32_t>> parents_;  // per split level
  std::vector<double> parent_r_;
  double reach_ = 0;  // the r the last list was proven with
  // Members evaluated so far, and the most a build may evaluate: a set whose
  // lists grow long (thin parts crowded within k of each other) gives up
  // early rather than after most of its cells.
  size_t evaluations_ = 0, budget_ = 0;
  std::vector<Interval> values_;
};

}  // namespace

bool buildBlendGrid(ir::InstanceSet& set, const ir::Node& node, double k,
                    const std::function<double(size_t, const glm::dvec3&)>& distance_of) {
  std::vector<double> lipschitz;
  std::vector<bool> exact;
  for (const ir::NodeRef& templ : node.children) {
    lipschitz.push_back(std::max(templ->lipschitz, 1.0));
    exact.push_back(templ->exact);
  }
  return BlendGridBuilder(set, node, k, distance_of, lipschitz, exact).build();
}

}  // namespace sdfc
