#include <cmath>
#include <unordered_set>

#include "passes/passes.h"

namespace sdfc {

glm::dmat3 rotationMatrix(glm::dvec3 axis, double degrees) {
  // Rodrigues' formula.
  const double a = glm::radians(degrees), c = std::cos(a), s = std::sin(a), t = 1 - c;
  const glm::dvec3 n = glm::normalize(axis);
  // glm is column-major: m[col][row].
  glm::dmat3 m;
  m[0] = {t * n.x * n.x + c, t * n.x * n.y + s * n.z, t * n.x * n.z - s * n.y};
  m[1] = {t * n.x * n.y - s * n.z, t * n.y * n.y + c, t * n.y * n.z + s * n.x};
  m[2] = {t * n.x * n.z + s * n.y, t * n.y * n.z - s * n.x, t * n.z * n.z + c};
  return m;
}

namespace {

// A constant translate/rotate/scale as an affine node, or false.
bool toAffine(ir::Node& n) {
  switch (n.kind) {
    case ir::NodeKind::Translate:
      if (!n.vec.isConst()) return false;
      n.linear = glm::dmat3(1.0);
      n.offset = -n.vec.value();
      n.scale = 1;
      break;
    case ir::NodeKind::Rotate:
      if (!n.amount.isConst()) return false;
      n.linear = glm::transpose(rotationMatrix(n.vec.value(), n.amount.value));
      n.offset = glm::dvec3(0);
      n.scale = 1;
      break;
    case ir::NodeKind::Scale:
      if (!n.amount.isConst()) return false;
      n.linear = glm::dmat3(1.0 / n.amount.value);
      n.offset = glm::dvec3(0);
      n.scale = n.amount.value;
      break;
    default: return false;
  }
  n.kind = ir::NodeKind::Affine;
  return true;
}

bool isIdentity(const ir::Node& n) {
  const glm::dmat3 d = n.linear - glm::dmat3(1.0);
  double e = 0;
  for (int c = 0; c < 3; ++c) e = std::max(e, glm::length(d[c]));
  return e < 1e-12 && glm::length(n.offset) < 1e-12 && std::fabs(n.scale - 1) < 1e-12;
}

void fuse(ir::NodeRef& ref, std::unordered_set<ir::Node*>& done) {
  ir::Node& n = *ref;
  if (done.insert(&n).second)
    for (ir::NodeRef& c : n.children) fuse(c, done);
  if (n.kind != ir::NodeKind::Affine && !toAffine(n)) return;
  // Fold an affine child into this one: l2 = A2 (A1 p + b1) + b2.
  while (n.children[0]->kind == ir::NodeKind::Affine && n.children[0]->definition.empty() &&
         n.children[0].use_count() == 1) {
    ir::NodeRef child = n.children[0];
    n.offset = child->linear * n.offset + child->offset;
    n.linear = child->linear * n.linear;
    n.scale *= child->scale;
    if (child->material >= 0) n.material = child->material;  // the inner one wins
    n.children = child->children;
  }
  // An identity map vanishes, unless it carries a material its child lacks.
  ir::NodeRef child = n.children[0];
  if (isIdentity(n) && n.definition.empty() && (n.material < 0 || n.material == child->material)) {
    ref = child;
  }
}

}  // namespace

void fuseTransforms(ir::Scene& scene) {
  if (!scene.root) return;
  std::unordered_set<ir::Node*> done;
  fuse(scene.root, done);
}

}  // namespace sdfc
