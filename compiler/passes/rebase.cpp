// The kernel's frame at the camera (docs/accuracy.md, "Far from the origin").
// float32 resolves a point to an ulp of its largest coordinate: a scene 1e5
// from the origin is drawn at ~0.008 however near the camera is. Moved by
// -origin in float64 before any constant is emitted, the rays start at 0 and
// a hit at distance t is resolved to ulps of t.
//
// The move is pushed down the tree as far as it commutes: into an affine map's
// offset (fused in float64: a placement 1e5 away becomes a small offset), a
// set's placements, a plane's offset, a mirror plane's offset, through unions,
// CSG, time-dependent translations and a vector scale. Where it cannot go
// (a shared definition, a primitive, a time-dependent rotation, an elongation,
// a limited repetition) a translation is put above the node: p + origin in
// float32, which is what world coordinates computed before. An infinite
// repetition only needs the move modulo its cell.
#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "eval/evaluator.h"
#include "passes/passes.h"

namespace sdfc {
namespace {

using glm::dvec3;

void countParents(const ir::NodeRef& n, std::unordered_map<const ir::Node*, int>& parents) {
  if (parents[n.get()]++ > 0) return;
  for (const ir::NodeRef& c : n->children) countParents(c, parents);
}

class Rebase {
 public:
  explicit Rebase(const ir::NodeRef& root) { countParents(root, parents_); }

  // Replaces ref, evaluated at world points p, by a node evaluated at p - c.
  void push(ir::NodeRef& ref, const dvec3& c) {
    if (c == dvec3(0)) return;
    ir::Node& n = *ref;
    if (parents_[&n] > 1 || !n.definition.empty()) return wrap(ref, c);
    switch (n.kind) {
      case ir::NodeKind::Union:
      case ir::NodeKind::Intersect:
      case ir::NodeKind::Subtract:
      case ir::NodeKind::Morph:
        for (ir::NodeRef& child : n.children) push(child, c);
        return;
      case ir::NodeKind::Affine:
        // local = L (p + c) + b
        n.offset += n.linear * c;
        return;
      case ir::NodeKind::Translate:
        // child(p + c - v) = child((p - v) + c), whatever v(time) is.
        return push(n.children[0], c);
      case ir::NodeKind::ScaleNonUniform:
        if (!n.vec.isConst()) return wrap(ref, c);
        return push(n.children[0], c / n.vec.value());
      case ir::NodeKind::Reflect:
        // Folding p + c about dot(x, m) = o is folding p about dot(x, m) = o - m.c, then + c.
        if (!n.vec.isConst() || !n.amount.isConst()) return wrap(ref, c);
        n.amount = ir::constant(n.amount.value - glm::dot(glm::normalize(n.vec.value()), c));
        return push(n.children[0], c);
      case ir::NodeKind::Repeat: {
        if (!n.vec.isConst()) return wrap(ref, c);
        // Whole cells of an infinite repetition change nothing.
        dvec3 rest = c;
        const dvec3 cell = n.vec.value();
        for (int a = 0; a < 3; ++a)
          if (cell[a] != 0 && n.count[a] == 0) rest[a] -= std::round(c[a] / cell[a]) * cell[a];
        return wrap(ref, rest);
      }
      case ir::NodeKind::Instances: {
        ir::InstanceSet& set = *n.instances;
        for (ir::Instance& inst : set.instances)
          inst.offset += inst.transform < 0 ? c : set.transforms[inst.transform].linear * c;
        // analyze builds them again, in the new frame.
        set.nodes.clear();
        set.grid = ir::InstanceGrid{};
        return;
      }
      case ir::NodeKind::Primitive:
        if (n.primitive == PrimitiveKind::Plane) {
          bool constant = true;
          for (const ir::Scalar& a : n.args) constant = constant && a.isConst();
          if (!constant) return wrap(ref, c);
          const dvec3 normal = glm::normalize(dvec3(n.args[0].value, n.args[1].value, n.args[2].value));
          n.args[3] = ir::constant(n.args[3].value - glm::dot(normal, c));
          return;
        }
        return wrap(ref, c);
      default: return wrap(ref, c);
    }
  }

 private:
  std::unordered_map<const ir::Node*, int> parents_;

  static void wrap(ir::NodeRef& ref, const dvec3& c) {
    if (c == dvec3(0)) return;
    auto moved = std::make_shared<ir::Node>();
    moved->kind = ir::NodeKind::Affine;
    moved->range = ref->range;
    moved->offset = c;
    moved->children = {ref};
    ref = moved;
  }
};

}  // namespace

double sceneDistanceFromCamera(const ir::Scene& scene) {
  if (!scene.root) return 0;
  const dvec3 eye = scene.camera.position;
  // The nearest surface (a lower bound where the field is one), at time 0.
  double nearest = std::fabs(Evaluator(scene).distance(eye));
  if (!std::isfinite(nearest)) nearest = 0;
  // The box around the finite parts (an endless floor has none): the
  // surfaces a camera looks at, beyond the floor it stands on.
  const ir::Node& root = *scene.root;
  Aabb finite_part;
  if (root.kind == ir::NodeKind::Union) {
    for (const ir::NodeRef& c : root.children)
      if (c->bounds.finite()) finite_part = finite_part.unite(c->bounds);
  } else if (root.bounds.finite()) {
    finite_part = root.bounds;
  }
  double to_box = 0;
  if (!finite_part.empty()) to_box = glm::length(glm::max(glm::max(finite_part.lo - eye, eye - finite_part.hi), dvec3(0)));
  return std::max(nearest, to_box);
}

bool wantsCameraFrame(const ir::Scene& scene) {
  const dvec3 eye = scene.camera.position;
  const double from_origin = std::max({std::fabs(eye.x), std::fabs(eye.y), std::fabs(eye.z)});
  // float32's error at a hit at distance t grows with |eye| + t, and the
  // hits nearest the camera, the ones that need it most, lie at least as far
  // as the scene is: within 4 times that of the origin the camera's frame
  // would gain at most 2 bits (and change every shader constant of the scenes
  // around the origin). Where the camera aims does not enter: a target 1e9
  // ahead kept a scene 6 away in world coordinates (issue 47 item 12).
  return from_origin > 4 * sceneDistanceFromCamera(scene);
}

void rebaseToCamera(ir::Scene& scene, Diagnostics& diags) {
  if (!scene.root || !wantsCameraFrame(scene)) return;
  const dvec3 c = scene.camera.position;
  Rebase(scene.root).push(scene.root, c);
  scene.origin += c;
  scene.camera.position -= c;
  scene.camera.target -= c;
  for (ir::SphereLight& l : scene.lights) l.position -= c;
  analyze(scene, diags);
}

}  // namespace sdfc
