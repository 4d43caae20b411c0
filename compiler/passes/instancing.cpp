// Per union, the choice between inline code and the data form: children that
// are placed copies of one shape (the same definition, or the same primitive
// kind with other constant parameters) become one Instances node when there
// are at least `threshold` of them; `instances(...)` below the threshold is
// written out as a union. The hierarchy over the copies is built here too.
#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <unordered_set>

#include "passes/passes.h"

namespace sdfc {
namespace {

using glm::dvec3;

// A union child seen as "template placed by an affine map".
struct Peeled {
  glm::dmat3 linear{1.0};
  dvec3 offset{0};
  double scale = 1;
  int material = -1;
  ir::NodeRef shape;
};

bool groupablePrimitive(const ir::Node& n) {
  if (n.kind != ir::NodeKind::Primitive || !n.definition.empty()) return false;
  if (n.primitive == PrimitiveKind::Plane || n.primitive == PrimitiveKind::Menger) return false;
  // A profile is evaluated at z = 0 by its extrude or revolve, not placed in space.
  if (primitiveInfo(n.primitive).profile) return false;
  for (const ir::Scalar& a : n.args)
    if (!a.isConst()) return false;
  return true;
}

bool containsInstances(const ir::Node& n) {
  if (n.kind == ir::NodeKind::Instances) return true;
  for (const ir::NodeRef& c : n.children)
    if (containsInstances(*c)) return true;
  return false;
}

// A union of one child is that child (a min or a blend of one value is
// the value): `union(material: m) { part }`, the way a part is given its own
// colour, is peeled like a transform, its material the part's unless the
// part names its own.
bool wrapper(const ir::Node& n) {
  return n.definition.empty() &&
         ((n.kind == ir::NodeKind::Affine) || (n.kind == ir::NodeKind::Union && n.children.size() == 1));
}

bool peel(const ir::NodeRef& child, Peeled& out) {
  ir::NodeRef n = child;
  while (wrapper(*n)) {
    if (n->kind == ir::NodeKind::Affine) {
      // Outer map first: local2 = A2 (A1 p + b1) + b2.
      out.offset = n->linear * out.offset + n->offset;
      out.linear = n->linear * out.linear;
      out.scale *= n->scale;
    }
    if (n->material >= 0) out.material = n->material;
    n = n->children[0];
  }
  if (groupablePrimitive(*n)) {
    if (n->material >= 0) out.material = n->material;
  } else if (n->definition.empty() || !n->bounds.finite() || containsInstances(*n) || ir::isProfile(*n)) {
    // (A set inside a set's template would run a loop per visit of the outer
    // loop, beyond what the loop-cap budget counts: nested sets stay code.)
    return false;
  }
  out.shape = n;
  return true;
}

// Key of the template a peeled child shares with others.
std::string templateKey(const Peeled& p) {
  if (p.shape->kind == ir::NodeKind::Primitive && p.shape->definition.empty())
    return std::string("primitive ") + primitiveInfo(p.shape->primitive).name;
  char buf[48];
  std::snprintf(buf, sizeof buf, "def %p", static_cast<const void*>(p.shape.get()));
  return buf;
}

// One set of the groups' copies: a template per group (a mixed set when
// there are several: each copy records its template's index).
ir::NodeRef makeInstances(const std::vector<std::vector<Peeled>>& groups, const ir::Scalar& smooth,
                          SourceRange range, const std::string& origin) {
  auto set = std::make_shared<ir::InstanceSet>();
  set->origin = origin;
  auto node = std::make_shared<ir::Node>();
  // Primitive groups whose copies differ carry their arguments per instance;
  // then every primitive group of the set does (one record layout).
  bool params = false;
  size_t param_count = 0;
  for (const std::vector<Peeled>& members : groups) {
    const ir::Node& first = *members[0].shape;
    if (first.kind != ir::NodeKind::Primitive || !first.definition.empty()) continue;
    param_count = std::max(param_count, first.args.size());
    for (const Peeled& m : members)
      for (size_t a = 0; a < first.args.size() && !params; ++a) params = m.shape->args[a].value != first.args[a].value;
  }
  if (params) set->param_count = static_cast<int>(param_count);
  for (size_t g = 0; g < groups.size(); ++g) {
    const ir::NodeRef& first = groups[g][0].shape;
    ir::NodeRef templ = first;
    const bool primitive = first->kind == ir::NodeKind::Primitive && first->definition.empty();
    if (primitive) {
      // A fresh template without the material (each instance carries its own).
      templ = std::make_shared<ir::Node>(*first);
      templ->material = -1;
    }
    node->children.push_back(templ);
    for (const Peeled& m : groups[g]) {
      ir::Instance inst;
      inst.offset = m.offset;
      inst.material = m.material;
      inst.templ = static_cast<std::int32_t>(g);
      if (m.linear != glm::dmat3(1.0) || m.scale != 1) {
        inst.transform = static_cast<int>(set->transforms.size());
        set->transforms.push_back({m.linear, m.scale});
      }
      set->instances.push_back(inst);
      if (set->param_count > 0) {
        const size_t at = set->params.size();
        set->params.resize(at + set->param_count, 0.0);
        if (primitive)
          for (size_t a = 0; a < m.shape->args.size(); ++a) set->params[at + a] = m.shape->args[a].value;
      }
    }
  }
  node->kind = ir::NodeKind::Instances;
  node->range = range;
  node->smooth = smooth;
  node->instances = set;
  return node;
}

// `instances(...)` with few copies: a plain union of placed templates.
ir::NodeRef expandInstances(const ir::Node& n) {
  const ir::InstanceSet& set = *n.instances;
  auto u = std::make_shared<ir::Node>();
  u->kind = ir::NodeKind::Union;
  u->range = n.range;
  u->material = n.material;
  u->definition = n.definition;
  u->smooth = n.smooth;
  for (size_t i = 0; i < set.size(); ++i) {
    ir::NodeRef shape = n.children[set.instances[i].templ];
    if (ir::takesParams(set, *shape)) {
      shape = std::make_shared<ir::Node>(*shape);
      for (size_t a = 0; a < shape->args.size(); ++a) shape->args[a] = ir::constant(set.paramsOf(i)[a]);
    }
    auto placed = std::make_shared<ir::Node>();
    placed->kind = ir::NodeKind::Affine;
    placed->range = n.range;
    placed->material = set.instances[i].material;
    placed->offset = set.instances[i].offset;
    if (set.instances[i].transform >= 0) {
      placed->linear = set.transforms[set.instances[i].transform].linear;
      placed->scale = set.transforms[set.instances[i].transform].scale;
    }
    placed->children = {shape};
    u->children.push_back(placed);
  }
  return u;
}

// Groups of copies far apart from each other, as index lists. A set's grid
// spans its bounds with about one cell per copy, so one copy 1e6 away from 45
// made cells of 950 that each held all 45 (a crowded cell: every step through
// the hierarchy). A set is cut at the empty gap between its copies' boxes
// along an axis where the two sides' boxes hold least volume, if that is
// under an eighth of the set's box (the cells of each side at least halve
// along every axis), and again within each side; a row or a uniform cloud has
// no such gap. Extents count at least one typical copy, as the grid's do.
std::vector<std::vector<std::uint32_t>> farGroups(const std::vector<Aabb>& boxes) {
  std::vector<double> sizes(boxes.size());
  for (size_t i = 0; i < boxes.size(); ++i) {
    const dvec3 e = boxes[i].hi - boxes[i].lo;
    sizes[i] = std::max({e.x, e.y, e.z});
  }
  std::nth_element(sizes.begin(), sizes.begin() + sizes.size() / 2, sizes.end());
  const double typical = std::max(sizes[sizes.size() / 2], 1e-9);
  auto volume = [&](const Aabb& b) {
    const dvec3 e = glm::max(b.hi - b.lo, dvec3(typical));
    return e.x * e.y * e.z;
  };
  std::vector<std::vector<std::uint32_t>> done, todo(1);
  todo[0].resize(boxes.size());
  std::iota(todo[0].begin(), todo[0].end(), 0u);
  std::vector<Aabb> prefix, suffix;
  while (!todo.empty()) {
    std::vector<std::uint32_t> group = std::move(todo.back());
    todo.pop_back();
    const size_t n = group.size();
    prefix.resize(n);
    suffix.resize(n);
    double best = 0.125;
    int best_axis = -1;
    size_t best_cut = 0;
    auto byLow = [&](int axis) {
      std::sort(group.begin(), group.end(), [&](std::uint32_t a, std::uint32_t b) {
        return boxes[a].lo[axis] < boxes[b].lo[axis] || (boxes[a].lo[axis] == boxes[b].lo[axis] && a < b);
      });
    };
    for (int axis = 0; axis < 3 && n > 1; ++axis) {
      byLow(axis);
      for (size_t k = 0; k < n; ++k) prefix[k] = (k ? prefix[k - 1] : Aabb{}).unite(boxes[group[k]]);
      for (size_t k = n; k-- > 0;) suffix[k] = (k + 1 < n ? suffix[k + 1] : Aabb{}).unite(boxes[group[k]]);
      const double all = volume(prefix[n - 1]);
      for (size_t k = 1; k < n; ++k) {
        if (!(boxes[group[k]].lo[axis] > prefix[k - 1].hi[axis])) continue;  // no empty gap
        const double ratio = (volume(prefix[k - 1]) + volume(suffix[k])) / all;
        if (ratio < best) {
          best = ratio;
          best_axis = axis;
          best_cut = k;
        }
      }
    }
    if (best_axis < 0) {
      done.push_back(std::move(group));
      continue;
    }
    byLow(best_axis);
    todo.emplace_back(group.begin(), group.begin() + best_cut);
    todo.emplace_back(group.begin() + best_cut, group.end());
  }
  return done;
}

// The copies `members` of set n (an Instances node) as a set of their own,
// with n's template, material and range.
ir::NodeRef subset(const ir::Node& n, const std::vector<std::uint32_t>& members, const std::string& origin) {
  const ir::InstanceSet& set = *n.instances;
  auto part = std::make_shared<ir::InstanceSet>();
  part->origin = origin;
  part->param_count = set.param_count;
  for (std::uint32_t i : members) {
    ir::Instance inst = set.instances[i];
    if (inst.transform >= 0) {
      part->transforms.push_back(set.transforms[inst.transform]);
      inst.transform = static_cast<int>(part->transforms.size()) - 1;
    }
    part->instances.push_back(inst);
    part->params.insert(part->params.end(), set.paramsOf(i), set.paramsOf(i) + set.param_count);
  }
  auto node = std::make_shared<ir::Node>(n);
  node->definition.clear();
  node->instances = part;
  return node;
}

class Former {
 public:
  // A scene that moves keeps smooth sets on their hierarchies (no blend grid).
  Former(const InstancingOptions& options, bool blend_grids) : options_(options), blend_grids_(blend_grids) {}

  void visit(ir::NodeRef& ref) {
    if (!done_.insert(ref.get()).second) return;
    for (ir::NodeRef& c : ref->children) visit(c);
    if (ref->kind == ir::NodeKind::Instances) {
      if (!dataForm(ref->instances->size()) || containsInstances(*ref->children[0])) {
        ir::NodeRef expanded = expandInstances(*ref);
        done_.insert(expanded.get());
        ref = expanded;
        return;
      }
      std::vector<ir::NodeRef> parts = splitFar(ref);
      if (parts.size() > 1) {
        // A union of the groups, taken into a sharp parent union (below).
        auto u = std::make_shared<ir::Node>();
        u->kind = ir::NodeKind::Union;
        u->range = ref->range;
        u->material = ref->material;
        u->definition = ref->definition;
        u->children = std::move(parts);
        done_.insert(u.get());
        if (u->definition.empty()) split_.insert(u.get());
        ref = u;
      }
      return;
    }
    if (ref->kind == ir::NodeKind::Subtract && sharp(*ref) && dataForm(ref->children.size() - 1)) {
      // max(a, -b1, ..., -bn) = max(a, -min(b1, ..., bn)): the shapes cut
      // away are a union, which may become data (a block with a thousand holes).
      auto cut = std::make_shared<ir::Node>();
      cut->kind = ir::NodeKind::Union;
      cut->range = ref->range;
      cut->children.assign(ref->children.begin() + 1, ref->children.end());
      ref->children.resize(1);
      ref->children.push_back(cut);
      done_.insert(cut.get());
      group(*cut);
      return;
    }
    if (ref->kind != ir::NodeKind::Union) return;
    if (sharp(*ref)) {
      std::vector<ir::NodeRef> flat;
      for (const ir::NodeRef& c : ref->children) {
        if (split_.count(c.get())) flat.insert(flat.end(), c->children.begin(), c->children.end());
        else flat.push_back(c);
      }
      ref->children = std::move(flat);
    }
    if (options_.threshold > 0 && ref->children.size() >= static_cast<size_t>(options_.threshold)) group(*ref);
  }

 private:
  const InstancingOptions& options_;
  bool blend_grids_;
  std::unordered_set<const ir::Node*> done_;

  // Unions of a split set's groups, which a sharp parent union takes in.
  std::unordered_set<const ir::Node*> split_;

  static bool sharp(const ir::Node& n) { return n.smooth.isConst() && n.smooth.value == 0; }

  // Set n (data form) as one set per group of copies far from the others
  // (farGroups); groups too small for the data form are code, and when there
  // are enough of them they form one set (they are apart: short lists). A
  // smooth set has no grid, and its hierarchy is exact whatever the spread.
  std::vector<ir::NodeRef> splitFar(const ir::NodeRef& n) {
    const ir::InstanceSet& set = *n->instances;
    if (!sharp(*n) || set.size() < 2) return {n};
    std::vector<Aabb> boxes(set.size());
    for (size_t i = 0; i < set.size(); ++i) {
      boxes[i] = instanceBounds(set, i, *n);
      if (!boxes[i].finite()) return {n};
    }
    const std::vector<std::vector<std::uint32_t>> groups = farGroups(boxes);
    if (groups.size() == 1) return {n};
    std::vector<ir::NodeRef> parts;
    std::vector<std::uint32_t> apart;
    for (const std::vector<std::uint32_t>& g : groups) {
      if (dataForm(g.size())) {
        parts.push_back(subset(*n, g, set.origin + ": " + std::to_string(g.size()) + " near each other"));
      } else {
        apart.insert(apart.end(), g.begin(), g.end());
      }
    }
    std::sort(apart.begin(), apart.end());
    if (dataForm(apart.size())) {
      parts.push_back(subset(*n, apart, set.origin + ": " + std::to_string(apart.size()) + " far apart"));
    } else if (!apart.empty()) {
      const ir::NodeRef few = expandInstances(*subset(*n, apart, set.origin));
      for (const ir::NodeRef& placed : few->children) {
        // Taken out of their union: the set's material is theirs.
        if (placed->material < 0) placed->material = n->material;
        parts.push_back(placed);
      }
    }
    for (const ir::NodeRef& p : parts) done_.insert(p.get());
    return parts;
  }

  bool dataForm(size_t count) const {
    return options_.threshold > 0 && count >= static_cast<size_t>(options_.threshold);
  }

  void group(ir::Node& u) {
    std::map<std::string, std::vector<size_t>> groups;
    std::vector<Peeled> peeled(u.children.size());
    std::vector<bool> ok(u.children.size(), false);
    for (size_t i = 0; i < u.children.size(); ++i) {
      ok[i] = peel(u.children[i], peeled[i]);
      if (ok[i]) groups[templateKey(peeled[i])].push_back(i);
    }
    // Which groups become data, and in which set. In a sharp union the
    // primitive groups (of every size) are one mixed set when together they
    // are enough: one grid lookup finds the parts near a point whatever their
    // kind, where a set per kind searched once per kind (kit-bashed parts of
    // five kinds, 1.8x; bench/results/many_parts.md). A point cloud keeps its
    // own set (its fast path). Not merged, measured slower on lavapipe, whose
    // 8 lanes in lockstep run every template any lane needs: definitions
    // (32 distinct chess pieces 2x slower than inline code) and smooth
    // unions, whose searches visit many leaves (1,000 blended parts of five
    // kinds 2.5x slower). There a group of enough copies is a set of its own.
    // A smooth union's primitives are merged too where the set gets a blend
    // grid (a list per cell instead of the searches): one blend of all its
    // parts, not one per kind blended again.
    std::vector<std::vector<std::string>> sets;
    std::vector<std::string> mixed;
    size_t mixed_count = 0;
    for (const auto& [key, members] : groups) {
      const bool cloud = key == "primitive sphere" && dataForm(members.size()) && cloudOf(members, peeled);
      const bool mixable = (sharp(u) || blend_grids_) && key.rfind("primitive ", 0) == 0;
      if (cloud || !mixable || (dataForm(members.size()) && groups.size() == 1)) {
        if (dataForm(members.size())) sets.push_back({key});
      } else {
        mixed.push_back(key);
        mixed_count += members.size();
      }
    }
    // Templates in the order the union names them (keys of definitions are
    // addresses, which differ from run to run).
    std::sort(mixed.begin(), mixed.end(),
              [&](const std::string& a, const std::string& b) { return groups[a][0] < groups[b][0]; });
    if (dataForm(mixed_count)) {
      sets.push_back(mixed);
    } else {
      // Too few in all: the groups large enough alone are still sets.
      for (const std::string& key : mixed)
        if (dataForm(groups[key].size())) sets.push_back({key});
    }
    std::vector<int> group_of(u.children.size(), -1);
    std::vector<ir::NodeRef> formed;
    for (const std::vector<std::string>& keys : sets) {
      std::vector<std::vector<Peeled>> members;
      size_t count = 0;
      std::string label;
      for (const std::string& key : keys) {
        const ir::Node& shape = *peeled[groups[key][0]].shape;
        if (!label.empty()) label += ", ";
        label += shape.definition.empty() ? primitiveInfo(shape.primitive).name : "'" + shape.definition + "'";
        members.emplace_back();
        for (size_t i : groups[key]) {
          members.back().push_back(std::move(peeled[i]));
          group_of[i] = static_cast<int>(formed.size());
        }
        count += groups[key].size();
      }
      const std::string origin = keys.size() > 4
                                     ? "union of " + std::to_string(count) + " parts of " + std::to_string(keys.size()) + " kinds"
                                     : "union of " + std::to_string(count) + " " + label;
      formed.push_back(makeInstances(members, u.smooth, u.range, origin));
    }
    if (formed.empty()) return;
    // Each set takes the place of its first member, as its far groups when
    // the union is sharp.
    std::vector<ir::NodeRef> kept;
    std::vector<bool> placed(formed.size(), false);
    for (size_t i = 0; i < u.children.size(); ++i) {
      if (group_of[i] < 0) {
        kept.push_back(u.children[i]);
      } else if (!placed[group_of[i]]) {
        placed[group_of[i]] = true;
        for (const ir::NodeRef& part : splitFar(formed[group_of[i]])) kept.push_back(part);
      }
    }
    u.children = std::move(kept);
  }

  // The copies are one sphere of constant radius placed by offsets alone.
  static bool cloudOf(const std::vector<size_t>& members, const std::vector<Peeled>& peeled) {
    const ir::Node& first = *peeled[members[0]].shape;
    for (size_t i : members) {
      const Peeled& p = peeled[i];
      if (p.linear != glm::dmat3(1.0) || p.scale != 1 || p.shape->args[0].value != first.args[0].value) return false;
    }
    return true;
  }
};

// Median split along the widest axis of the centres: depth stays
// ceil(log2(n / leaf)) + 1, which bounds the shader's stack.
struct BvhBuilder {
  std::vector<Aabb> boxes;
  std::vector<dvec3> centres;
  std::vector<std::uint32_t> order;
  std::vector<ir::BvhNode> nodes;
  int depth = 0;

  std::uint32_t build(std::uint32_t begin, std::uint32_t end, int level) {
    depth = std::max(depth, level);
    const std::uint32_t index = static_cast<std::uint32_t>(nodes.size());
    nodes.emplace_back();
    Aabb box, centre_box;
    for (std::uint32_t i = begin; i < end; ++i) {
      box = box.unite(boxes[order[i]]);
      centre_box = centre_box.unite({centres[order[i]], centres[order[i]]});
    }
    nodes[index].box = box;
    if (end - begin <= ir::kBvhLeafSize) {
      nodes[index].first = begin;
      nodes[index].count = end - begin;
      return index;
    }
    const dvec3 extent = centre_box.hi - centre_box.lo;
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
    const std::uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end,
                     [&](std::uint32_t a, std::uint32_t b) { return centres[a][axis] < centres[b][axis]; });
    build(begin, mid, level + 1);
    const std::uint32_t right = build(mid, end, level + 1);
    nodes[index].first = right;
    nodes[index].count = 0;
    return index;
  }
};

}  // namespace

Aabb instanceLocalBounds(const ir::InstanceSet& set, size_t i, const ir::Node& n) {
  const ir::Node& templ = *n.children[set.instances[i].templ];
  if (!ir::takesParams(set, templ)) return templ.bounds;
  return primitiveInfo(templ.primitive).bounds(set.paramsOf(i));
}

Aabb instanceBounds(const ir::InstanceSet& set, size_t i, const ir::Node& n) {
  const ir::Instance& inst = set.instances[i];
  const Aabb local = instanceLocalBounds(set, i, n);
  if (inst.transform < 0) return {local.lo - inst.offset, local.hi - inst.offset};
  // local = A p + b  =>  p = A^-1 (local - b)
  const glm::dmat3 inv = glm::inverse(set.transforms[inst.transform].linear);
  return transformBox(local, inv, -(inv * inst.offset));
}

void buildInstanceHierarchy(ir::InstanceSet& set, const ir::Node& node) {
  const size_t n = set.size();
  BvhBuilder b;
  b.boxes.resize(n);
  b.centres.resize(n);
  for (size_t i = 0; i < n; ++i) {
    b.boxes[i] = instanceBounds(set, i, node);
    b.centres[i] = b.boxes[i].center();
  }
  b.order.resize(n);
  std::iota(b.order.begin(), b.order.end(), 0u);
  b.nodes.reserve(2 * (n / ir::kBvhLeafSize + 1));
  if (n > 0) b.build(0, static_cast<std::uint32_t>(n), 1);
  // Instances (and their parameters) in leaf order.
  std::vector<ir::Instance> instances(n);
  std::vector<double> params(set.params.size());
  for (size_t i = 0; i < n; ++i) {
    instances[i] = set.instances[b.order[i]];
    for (int a = 0; a < set.param_count; ++a)
      params[i * set.param_count + a] = set.params[b.order[i] * set.param_count + a];
  }
  set.instances = std::move(instances);
  set.params = std::move(params);
  set.nodes = std::move(b.nodes);
  set.depth = b.depth;
}

void formInstances(ir::Scene& scene, const InstancingOptions& options) {
  if (!scene.root) return;
  Former former(options, !scene.uses_time);
  former.visit(scene.root);
}

}  // namespace sdfc
