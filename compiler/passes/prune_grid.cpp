// Lipschitz pruning of the scene's root union over a grid (after Barbier et
// al., "Lipschitz Pruning", Eurographics 2025, for a sharp union of parts):
// part i's field f_i has Lipschitz constant L_i, so over a block of half
// diagonal r about c it lies in [f_i(c) - L_i r, f_i(c) + L_i r]. A part whose
// lower end is above the least upper end m is farther than some other part
// everywhere in the block: the union is the same without it. Blocks halve
// until one part is left or a block is one cell; each cell keeps a mask of
// its parts. The shader evaluates a part only where some lane of its group
// needs it (subgroupAny), so its result equals the whole union's.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "eval/evaluator.h"
#include "passes/passes.h"

namespace sdfc {
namespace {

using glm::dvec3;
using glm::ivec3;

constexpr int kCellsOnLongestAxis = 48;

bool sharpUnion(const ir::Node& n) {
  return n.kind == ir::NodeKind::Union && n.smooth.isConst() && n.smooth.value == 0;
}

// Whether the part's field is one function of space with its Lipschitz
// constant (what the bound needs): the same at every time, no mesh grid, no
// repeat whose copies are not all tried.
bool prunable(const ir::Node& n) {
  for (const ir::Scalar& a : n.args)
    if (!a.isConst()) return false;
  if (!n.smooth.isConst() || !n.amount.isConst() || !n.vec.isConst()) return false;
  if (n.kind == ir::NodeKind::Mesh) return false;
  if (n.kind == ir::NodeKind::Repeat)
    for (int a = 0; a < 3; ++a)
      if ((a == 0 ? n.vec.x : a == 1 ? n.vec.y : n.vec.z).value != 0 && !repeatCells(n, a).covered) return false;
  if (n.kind == ir::NodeKind::RepeatPolar && n.count.x > 1 && !polarSectors(n).covered) return false;
  if (!std::isfinite(n.lipschitz) || n.lipschitz <= 0) return false;
  for (const ir::NodeRef& c : n.children)
    if (!prunable(*c)) return false;
  return true;
}

// A top-level sphere the emitter may intersect in closed form instead of
// marching it: it may leave the union, so no pruning may rely on it.
bool mayBeAnalytic(const ir::Node& n) {
  const ir::Node* s = &n;
  if (s->kind == ir::NodeKind::Affine && s->definition.empty() && s->children.size() == 1) s = s->children[0].get();
  return s->kind == ir::NodeKind::Primitive && s->primitive == PrimitiveKind::Sphere && s->definition.empty();
}

class PruneGridBuilder {
 public:
  PruneGridBuilder(const ir::Scene& scene, ir::PruneGrid& g, std::vector<int> pruned)
      : eval_(scene), g_(g), pruned_(std::move(pruned)) {
    for (int i : pruned_) lipschitz_.push_back(std::max(1.0, g_.parts[i]->lipschitz));
    for (int i : pruned_) cost_.push_back(std::max(g_.parts[i]->cost, 1e-3));
    for (double c : cost_) total_cost_ += c;
  }

  // Cells [a, b) with the parts (indices into pruned_) that may be nearest there.
  void block(ivec3 a, ivec3 b, const std::vector<int>& active) {
    const double margin = 0.01 * g_.cell;  // float32 lookups near a face
    const dvec3 lo = g_.lo + dvec3(a) * g_.cell - margin, hi = g_.lo + dvec3(b) * g_.cell + margin;
    const dvec3 c = (lo + hi) * 0.5;
    const double r = glm::length(hi - lo) * 0.5;
    std::vector<double> v(active.size());
    double m = std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < active.size(); ++k) {
      const int i = pruned_[active[k]];
      v[k] = eval_.evalNode(*g_.parts[i], c, g_.inherited[i]).distance;
      if (std::isnan(v[k])) v[k] = -std::numeric_limits<double>::infinity();  // keep it
      m = std::min(m, v[k] + lipschitz_[active[k]] * r);
    }
    // A part farther by less than this stays (the shader's float32 values).
    const double tolerance = 0.01 * g_.cell;
    std::vector<int> keep;
    double lowest = std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < active.size(); ++k) {
      const double low = v[k] - lipschitz_[active[k]] * r;
      if (low <= m + tolerance) keep.push_back(active[k]);
      lowest = std::min(lowest, low);
    }
    const ivec3 size = b - a;
    if (keep.size() > 1 && (size.x > 1 || size.y > 1 || size.z > 1)) {
      const ivec3 mid = a + size / 2;
      for (int z = 0; z < (size.z > 1 ? 2 : 1); ++z)
        for (int y = 0; y < (size.y > 1 ? 2 : 1); ++y)
          for (int x = 0; x < (size.x > 1 ? 2 : 1); ++x) {
            const ivec3 sa(x ? mid.x : a.x, y ? mid.y : a.y, z ? mid.z : a.z);
            const ivec3 sb(size.x > 1 ? (x ? b.x : mid.x) : b.x, size.y > 1 ? (y ? b.y : mid.y) : b.y,
                           size.z > 1 ? (z ? b.z : mid.z) : b.z);
            block(sa, sb, keep);
          }
      return;
    }
    std::array<std::uint32_t, 4> mask{0, 0, 0, 0};
    double kept = 0;
    for (int k : keep) {
      const int bit = g_.bit[pruned_[k]];
      mask[bit / ir::kPruneBitsPerWord] |= 1u << (bit % ir::kPruneBitsPerWord);
      kept += cost_[k];
    }
    const size_t cells = size_t(size.x) * size.y * size.z;
    // Near a surface: some part may come within two cells of the block.
    const bool near = lowest <= 2 * g_.cell;
    kept_ += kept / total_cost_ * double(cells);
    if (near) {
      kept_near_ += kept / total_cost_ * double(cells);
      near_cells_ += double(cells);
    }
    for (int z = a.z; z < b.z; ++z)
      for (int y = a.y; y < b.y; ++y)
        for (int x = a.x; x < b.x; ++x) g_.masks[size_t(x) + size_t(g_.dims.x) * (size_t(y) + size_t(g_.dims.y) * z)] = mask;
  }

  double keptCost() const { return kept_ / double(g_.masks.size()); }
  double keptCostNear() const { return near_cells_ > 0 ? kept_near_ / near_cells_ : 1; }

 private:
  Evaluator eval_;
  ir::PruneGrid& g_;
  std::vector<int> pruned_;  // parts with a bit
  std::vector<double> lipschitz_, cost_;
  double total_cost_ = 0;
  double kept_ = 0, kept_near_ = 0, near_cells_ = 0;
};

}  // namespace

std::shared_ptr<const ir::PruneGrid> buildPruneGrid(const ir::Scene& scene) {
  if (!scene.root || !sharpUnion(*scene.root)) return nullptr;
  const auto t0 = std::chrono::steady_clock::now();
  auto g = std::make_shared<ir::PruneGrid>();
  // Nested sharp unions are flattened level by level while the parts fit a mask.
  std::vector<std::pair<ir::NodeRef, int>> parts;
  for (const ir::NodeRef& c : scene.root->children) parts.push_back({c, -1});
  for (bool grew = true; grew;) {
    grew = false;
    std::vector<std::pair<ir::NodeRef, int>> next;
    for (const auto& [n, inherited] : parts) {
      if (sharpUnion(*n)) {
        const int m = n->material >= 0 ? n->material : inherited;
        for (const ir::NodeRef& c : n->children) next.push_back({c, m});
      } else {
        next.push_back({n, inherited});
      }
    }
    if (next.size() != parts.size() && next.size() <= size_t(ir::kPruneMaxParts)) {
      parts = std::move(next);
      grew = true;
    }
  }
  if (parts.size() > size_t(ir::kPruneMaxParts)) return nullptr;
  Aabb box;
  std::vector<int> pruned;
  for (size_t i = 0; i < parts.size(); ++i) {
    const ir::Node& n = *parts[i].first;
    g->parts.push_back(parts[i].first);
    g->inherited.push_back(parts[i].second);
    const bool direct = std::find(scene.root->children.begin(), scene.root->children.end(),
                                                parts[i].first) != scene.root->children.end();
    const bool ok = n.bounds.finite() && !(direct && mayBeAnalytic(n)) && prunable(n);
    g->bit.push_back(ok ? int(pruned.size()) : -1);
    if (ok) {
      pruned.push_back(int(i));
      box = box.unite(n.bounds);
    }
  }
  if (pruned.size() < 2) return nullptr;
  const dvec3 extent = glm::max(box.hi - box.lo, dvec3(1e-9));
  const double longest = std::max(extent.x, std::max(extent.y, extent.z));
  g->cell = longest / kCellsOnLongestAxis;
  g->dims = glm::clamp(ivec3(glm::ceil(extent / g->cell)), ivec3(1), ivec3(kCellsOnLongestAxis));
  // Centred on the parts' box (the last cells may reach past it).
  g->lo = box.center() - dvec3(g->dims) * g->cell * 0.5;
  g->masks.assign(size_t(g->dims.x) * g->dims.y * g->dims.z, {0, 0, 0, 0});
  PruneGridBuilder builder(scene, *g, pruned);
  std::vector<int> all(pruned.size());
  for (size_t k = 0; k < all.size(); ++k) all[k] = int(k);
  builder.block(ivec3(0), g->dims, all);
  g->kept_cost = builder.keptCost();
  g->kept_cost_near = builder.keptCostNear();
  g->build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return g;
}

void planPruneGrid(ir::Scene& scene) {
  if (std::shared_ptr<const ir::PruneGrid> g = buildPruneGrid(scene)) scene.root->prune = std::move(g);
}

std::array<std::uint32_t, 4> pruneMaskAt(const ir::PruneGrid& g, const glm::dvec3& p) {
  // As the shader's sdPruneMask: every part outside the grid (and for NaN).
  const dvec3 q = (p - g.lo) / g.cell;
  if (!(q.x >= 0 && q.y >= 0 && q.z >= 0 && q.x < g.dims.x && q.y < g.dims.y && q.z < g.dims.z)) {
    constexpr std::uint32_t all = (1u << ir::kPruneBitsPerWord) - 1;
    return {all, all, all, all};
  }
  const ivec3 c = glm::min(ivec3(q), g.dims - 1);
  return g.masks[size_t(c.x) + size_t(g.dims.x) * (size_t(c.y) + size_t(g.dims.y) * c.z)];
}

}  // namespace sdfc
