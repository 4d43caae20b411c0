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
#include <atomic>
#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <mutex>
#include <queue>
#include <thread>

#include "passes/passes.h"

namespace sdfc {
namespace {

using glm::dvec3;

// Cells: kBlendCellsPerInstance per member, or where that grid can be listed
// (buildBlendGrid) kSmallSetCellsPerInstance per member up to kSmallSetCells
// in all. A cell lists every member whose interval over it (the cell's
// diagonal wide) can come within k of the nearest, so finer cells list
// fewer, for more building time (a list per cell) and memory. Round 14, CPU
// ms a sample against 4 per member (bench/results/blend_cells.md): trees of
// 100-1,000 twigs 0.53-0.76x, kit-bashes 0.80-0.92x, molecules 0.93-1.03x; at
// 10,000 parts finer cells gained nothing and doubled the build (0.9 ->
// 1.8 s), hence the cap.
// kSplitAbove: the list length above which a cell is split into octants (half
// the interval width); 8 took the least CPU time among 4-16.
constexpr double kBlendCellsPerInstance = 4.0;
constexpr double kSmallSetCellsPerInstance = 64.0;
constexpr double kSmallSetCells = 32768;
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

struct Interval {
  double lo, hi;
};

// What every worker reads: the set, its members' boxes and constants, and
// the grid's geometry (fixed before any list is built).
struct Shared {
  Shared(const ir::InstanceSet& set_in, double k_in, const std::function<double(size_t, const dvec3&)>& distance_of_in,
         const std::vector<double>& lipschitz_in, const std::vector<bool>& exact_in)
      : set(set_in), k(k_in), distance_of(distance_of_in), lipschitz(lipschitz_in), exact(exact_in),
        all_exact(std::find(exact_in.begin(), exact_in.end(), false) == exact_in.end()) {}
  const ir::InstanceSet& set;
  double k;
  const std::function<double(size_t, const dvec3&)>& distance_of;
  const std::vector<double>& lipschitz;
  const std::vector<bool>& exact;
  bool all_exact;
  // What the nodes above may take off the set's value (ir::Node::lowered):
  // a far cell's bound and the margin must exceed it.
  double lowered = 0;
  std::vector<Aabb> boxes;
  double slack = 0;
  size_t budget = 0;
  size_t cells = 0;  // dims.x * dims.y * dims.z
  // Member evaluations of all slices so far: a build over its budget stops.
  std::atomic<size_t> evaluations{0};
  std::atomic<bool> failed{false};
};

// One z slice of cells, built on its own: its cells' entries and octants,
// both numbered from 0 (an octant as cells + its place here); build() joins
// the slices in z order, which is the numbering of one pass over the cells.
struct Slice {
  std::vector<std::uint32_t> first;  // per cell of the slice, then per octant
  std::vector<std::int32_t> count;
  std::vector<double> reach;
  std::vector<std::uint32_t> entries;
  size_t cells = 0;  // cells of the slice (its octants follow)
  int longest = 0, splits = 0;
  size_t evaluations = 0;
};

// The lists of one slice at a time (one worker per thread): scratch state only.
class SliceBuilder {
 public:
  explicit SliceBuilder(Shared& shared) : sh_(shared) {}

  // Lists slice z of `g`'s cells into `out`; false where the set cannot be listed.
  bool build(const ir::InstanceGrid& g, int z, Slice& out) {
    out_ = &out;
    const size_t cells = size_t(g.dims.x) * g.dims.y;
    out.cells = cells;
    out.first.assign(cells, 0);
    out.count.assign(cells, 0);
    out.reach.assign(cells, 0);
    for (int y = 0; y < g.dims.y; ++y)
      for (int x = 0; x < g.dims.x; ++x) {
        const size_t c = size_t(x) + size_t(g.dims.x) * size_t(y);
        const dvec3 lo = g.lo + dvec3(x, y, z) * g.cell;
        if (sh_.failed.load(std::memory_order_relaxed)) return false;
        if (far(Aabb{lo, lo + g.cell}, c)) continue;
        if (!cellList(Aabb{lo, lo + g.cell}, c, 0)) return false;
        if (out.entries.size() > ir::kGridMaxEntry) return false;
      }
    return true;
  }

 private:
  // Counts evaluations; false once the whole build is over its budget.
  bool spend(size_t evaluations) {
    out_->evaluations += evaluations;
    return sh_.evaluations.fetch_add(evaluations, std::memory_order_relaxed) + evaluations <= sh_.budget;
  }

  void store(size_t c) {
    Slice& s = *out_;
    s.longest = std::max(s.longest, static_cast<int>(list_.size()));
    s.first[c] = static_cast<std::uint32_t>(s.entries.size());
    s.count[c] = static_cast<std::int32_t>(list_.size());
    for (std::uint32_t i : list_) s.entries.push_back(i);
  }

  // Members whose boxes lie within r of `box`: from the hierarchy, or
  // (`within`) from a list that holds every member within r of it.
  void near(const Aabb& box, double r, std::vector<std::uint32_t>& out,
            const std::vector<std::uint32_t>* within = nullptr) {
    out.clear();
    const double rr = r * r;
    if (within) {
      for (std::uint32_t i : *within)
        if (sh_.boxes[i].gapSquared(box) < rr) out.push_back(i);
      return;
    }
    stack_.assign(1, 0);
    while (!stack_.empty()) {
      const std::uint32_t ni = stack_.back();
      stack_.pop_back();
      const ir::BvhNode& node = sh_.set.nodes[ni];
      if (node.box.gapSquared(box) >= rr) continue;
      if (node.count == 0) {
        stack_.push_back(ni + 1);
        stack_.push_back(node.first);
        continue;
      }
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i)
        if (sh_.boxes[i].gapSquared(box) < rr) out.push_back(i);
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
    Slice& s = *out_;
    s.splits = std::max(s.splits, level + 1);
    const size_t sub = s.count.size();
    s.first[c] = static_cast<std::uint32_t>(sh_.cells + (sub - s.cells));
    s.count[c] = ir::kGridSplit;
    s.first.resize(sub + 8);
    s.count.resize(sub + 8);
    s.reach.resize(sub + 8, 0);
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
    if (!sh_.all_exact) return false;
    nearest(box, 1, candidates_);
    const double g = sh_.boxes[candidates_[0]].distance(box);
    if (g - 1.25 * sh_.k < std::max(0.5 * glm::length(box.hi - box.lo), 1.01 * sh_.lowered)) return false;
    Slice& s = *out_;
    s.first[c] = static_cast<std::uint32_t>(s.entries.size());
    s.count[c] = 0;
    s.reach[c] = g - 1.25 * sh_.k;
    return true;
  }

  // The `count` members whose boxes are nearest `box`, best first.
  void nearest(const Aabb& box, size_t count, std::vector<std::uint32_t>& out) {
    out.clear();
    using Entry = std::pair<double, std::int64_t>;  // gap squared; node index, or -1 - member
    std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> queue;
    const std::vector<ir::BvhNode>& nodes = sh_.set.nodes;
    queue.push({nodes[0].box.gapSquared(box), 0});
    while (!queue.empty() && out.size() < count) {
      const auto [gap, id] = queue.top();
      queue.pop();
      if (id < 0) {
        out.push_back(static_cast<std::uint32_t>(-1 - id));
        continue;
      }
      const ir::BvhNode& node = nodes[size_t(id)];
      if (node.count == 0) {
        queue.push({nodes[size_t(id) + 1].box.gapSquared(box), id + 1});
        queue.push({nodes[node.first].box.gapSquared(box), node.first});
        continue;
      }
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i)
        queue.push({sh_.boxes[i].gapSquared(box), -1 - std::int64_t(i)});
    }
  }

  // An octant's candidates come from its cell's (`parent`, every member
  // within `parent_r` of the cell): the octant needs no more than that, as
  // its least upper value is at most the cell's.
  bool list(const Aabb& box, std::vector<std::uint32_t>& out, const std::vector<std::uint32_t>* parent = nullptr,
            double parent_r = 0) {
    const dvec3 c = box.center();
    const double h = 0.5 * glm::length(box.hi - box.lo);
    const ir::InstanceSet& set = sh_.set;
    // A first reach from the members of the nearest few boxes: the least of
    // their upper values plus k (found best first, so a cell far from the
    // parts does not gather the many between).
    double r = 2 * h + sh_.k;
    if (!parent) {
      nearest(box, 8, candidates_);
      double least = std::numeric_limits<double>::infinity();
      out_->evaluations += candidates_.size();
      sh_.evaluations.fetch_add(candidates_.size(), std::memory_order_relaxed);
      for (std::uint32_t i : candidates_)
        least = std::min(least, sh_.distance_of(i, c) + sh_.lipschitz[set.instances[i].templ] * h);
      r = least + sh_.k + sh_.slack;
    }
    for (;;) {
      near(box, r, candidates_, parent && r <= parent_r ? parent : nullptr);
      if (candidates_.size() > kMaxCandidates) return false;
      if (candidates_.empty()) {
        r *= 2;
        continue;
      }
      if (!spend(candidates_.size())) return false;
      values_.resize(candidates_.size());
      double least_hi = std::numeric_limits<double>::infinity();
      for (size_t j = 0; j < candidates_.size(); ++j) {
        const std::uint32_t i = candidates_[j];
        const double v = sh_.distance_of(i, c), spread = sh_.lipschitz[set.instances[i].templ] * h;
        // A cell apart from an exact member's box: the member is at least that
        // far (a box touching the cell bounds nothing: the member may be
        // inside; a bound's value may lie below its box's distance).
        const double apart = sh_.exact[set.instances[i].templ] ? sh_.boxes[i].distance(box) : 0;
        values_[j] = {apart > 0 ? std::max(v - spread, apart) : v - spread, v + spread};
        least_hi = std::min(least_hi, values_[j].hi);
      }
      const double cut = least_hi + sh_.k + sh_.slack;
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
        const std::int32_t ta = set.instances[a].templ, tb = set.instances[b].templ;
        return ta != tb ? ta < tb : a < b;
      });
      return true;
    }
  }

  Shared& sh_;
  Slice* out_ = nullptr;
  std::vector<std::uint32_t> candidates_, list_, stack_;
  std::vector<std::vector<std::uint32_t>> parents_;  // per split level
  std::vector<double> parent_r_;
  double reach_ = 0;  // the r the last list was proven with
  std::vector<Interval> values_;
};

// Slices a build may list at once: the worker threads beside the caller's.
unsigned blendGridThreads(size_t cells) {
  // A small grid is not worth a thread's start (about 0.1 ms).
  if (cells < 4096) return 1;
  return std::clamp(std::thread::hardware_concurrency(), 1u, 8u);
}

class BlendGridBuilder {
 public:
  BlendGridBuilder(ir::InstanceSet& set, const ir::Node& node, double k,
                   const std::function<double(size_t, const dvec3&)>& distance_of,
                   const std::vector<double>& lipschitz, const std::vector<bool>& exact, unsigned threads)
      : set_(set), node_(node), threads_(threads),
        sh_(set, k, distance_of, lipschitz, exact) {}

  // Builds the grid at about `target` cells; false (the set left without a
  // grid) where it cannot be listed within the budget (at most `budget`).
  bool build(double target, size_t budget = SIZE_MAX) {
    ir::InstanceGrid& g = set_.grid;
    g = ir::InstanceGrid{};
    const size_t n = set_.size();
    if (n == 0 || set_.nodes.empty()) return false;
    std::vector<Aabb>& boxes = sh_.boxes;
    const double k = sh_.k;
    sh_.lowered = node_.lowered;
    boxes.resize(n);
    std::vector<double> sizes(n);
    Aabb bounds;
    for (size_t i = 0; i < n; ++i) {
      boxes[i] = instanceBounds(set_, i, node_);
      if (!boxes[i].finite()) return false;
      bounds = bounds.unite(boxes[i]);
      const dvec3 e = boxes[i].hi - boxes[i].lo;
      sizes[i] = std::max({e.x, e.y, e.z});
    }
    std::nth_element(sizes.begin(), sizes.begin() + n / 2, sizes.end());
    const double typical = std::max(sizes[n / 2], 1e-9);
    const dvec3 extent = glm::max(bounds.hi - bounds.lo, dvec3(typical));
    const double max_cells = std::min<double>(target + 4096, double(ir::kGridMaxEntry));
    double cell = std::max(std::cbrt(extent.x * extent.y * extent.z / target), 0.5 * typical);
    // The box is the bounds grown by 1.25 k plus half a cell: outside it every
    // member is that far, the blend at least half a cell (a positive bound).
    dvec3 dims;
    double pad = 0;
    for (;;) {
      pad = 1.25 * k + std::max(0.5 * cell, 1.01 * node_.lowered);
      dims = glm::ceil((bounds.hi - bounds.lo + 2.0 * pad) / cell);
      if (dims.x * dims.y * dims.z <= max_cells) break;
      cell *= 1.05;
    }
    g.cell = cell;
    g.dims = glm::ivec3(dims);
    g.lo = bounds.lo - pad;
    g.margin = pad - 1.25 * k;
    g.blend = true;
    sh_.budget = std::min(budget, kEvaluationsPerMember * n + kEvaluationsAtLeast);
    // float32 rounding of the kernel's values (coordinates up to `scale`)
    // must not turn a proven drop or reset into a near miss.
    const dvec3 hi = g.lo + dims * cell;
    const double scale = std::max(glm::length(glm::max(glm::abs(g.lo), glm::abs(hi))), glm::length(extent));
    sh_.slack = 1e-3 * k + 1e-5 * scale;
    sh_.cells = size_t(g.dims.x) * g.dims.y * g.dims.z;
    if (!listSlices(g)) return fail();
    return true;
  }

  // Member evaluations the last build spent.
  size_t evaluations() const { return sh_.evaluations.load(); }

 private:
  bool fail() {
    set_.grid = ir::InstanceGrid{};
    return false;
  }

  // The z slices' lists, on several threads where the grid is large (each
  // slice alone, so the threads share only the budget), joined in z order:
  // the same grid as one pass over the cells, bit for bit. A thread's
  // exception (out of memory) is the caller's, after every thread is joined.
  bool listSlices(ir::InstanceGrid& g) {
    std::vector<Slice> slices(size_t(g.dims.z));
    std::atomic<int> next{0};
    std::vector<std::exception_ptr> errors;
    std::mutex errors_mutex;
    auto work = [&] {
      try {
        SliceBuilder builder(sh_);
        for (int z = next++; z < g.dims.z && !sh_.failed.load(); z = next++)
          if (!builder.build(g, z, slices[size_t(z)])) sh_.failed = true;
      } catch (...) {
        sh_.failed = true;
        const std::lock_guard<std::mutex> lock(errors_mutex);
        errors.push_back(std::current_exception());
      }
    };
    std::vector<std::thread> threads;
    for (unsigned t = 1; t < (threads_ > 0 ? threads_ : blendGridThreads(sh_.cells)); ++t) threads.emplace_back(work);
    work();
    for (std::thread& t : threads) t.join();
    if (!errors.empty()) std::rethrow_exception(errors.front());
    size_t evaluations = 0, entries = 0, octants = 0;
    for (const Slice& s : slices) {
      evaluations += s.evaluations;
      entries += s.entries.size();
      octants += s.count.size() - s.cells;
    }
    if (sh_.failed || evaluations > sh_.budget || entries > ir::kGridMaxEntry) return false;
    g.first.resize(sh_.cells + octants);
    g.count.resize(sh_.cells + octants);
    g.reach.resize(sh_.cells + octants);
    g.entries.reserve(entries);
    size_t cell_at = 0, octant_at = sh_.cells;
    for (const Slice& s : slices) {
      // Entries and octants numbered after the slices before this one.
      const auto entry_base = static_cast<std::uint32_t>(g.entries.size());
      const auto octant_shift = static_cast<std::uint32_t>(octant_at - sh_.cells);
      for (size_t j = 0; j < s.count.size(); ++j) {
        const size_t to = j < s.cells ? cell_at + j : octant_at + (j - s.cells);
        g.count[to] = s.count[j];
        g.reach[to] = s.reach[j];
        g.first[to] = s.count[j] == ir::kGridSplit ? s.first[j] + octant_shift : s.first[j] + entry_base;
      }
      g.entries.insert(g.entries.end(), s.entries.begin(), s.entries.end());
      cell_at += s.cells;
      octant_at += s.count.size() - s.cells;
      g.longest = std::max(g.longest, s.longest);
      g.splits = std::max(g.splits, s.splits);
    }
    return true;
  }

  ir::InstanceSet& set_;
  const ir::Node& node_;
  unsigned threads_;  // 0: blendGridThreads
  Shared sh_;
};

}  // namespace

bool buildBlendGrid(ir::InstanceSet& set, const ir::Node& node, double k,
                    const std::function<double(size_t, const glm::dvec3&)>& distance_of, unsigned threads) {
  std::vector<double> lipschitz;
  std::vector<bool> exact;
  for (const ir::NodeRef& templ : node.children) {
    lipschitz.push_back(std::max(templ->lipschitz, 1.0));
    exact.push_back(templ->exact);
  }
  const double n = double(set.size());
  const double fine = std::min(kSmallSetCellsPerInstance * n, kSmallSetCells), coarse = kBlendCellsPerInstance * n;
  BlendGridBuilder first(set, node, k, distance_of, lipschitz, exact, threads);
  if (!first.build(coarse)) return false;
  // Then the finer grid, where it has at least twice the cells (a set of at
  // most 4,096 members), within 4x the coarse one's evaluations (it took
  // 1.2-2.1x on trees, kit-bashes and molecules of 100-1,000 parts); a blend
  // radius wide against its cells lists many members in each, and the coarse
  // grid stays.
  if (fine < 2 * coarse) return true;
  ir::InstanceGrid kept = set.grid;
  if (BlendGridBuilder(set, node, k, distance_of, lipschitz, exact, threads).build(fine, 4 * first.evaluations()))
    return true;
  set.grid = std::move(kept);
  return true;
}

}  // namespace sdfc
