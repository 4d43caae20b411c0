#include "eval/block_evaluator.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "passes/deform.h"
#include "passes/passes.h"
#include "shapes/primitive_blocks.h"

namespace sdfc {

using glm::dvec3;

namespace {

// smoothMin and smoothMax (evaluator.cpp) as they are, where the block's
// loops can inline them; the tests hold the two to the same bits.
inline double blendMin(double a, double b, double k) {
  if (k <= 0) return std::min(a, b);
  const double h = std::max(k - std::fabs(a - b), 0.0) / k;
  return std::min(a, b) - h * h * k * 0.25;
}

inline double blendMax(double a, double b, double k) { return -blendMin(-a, -b, k); }

}  // namespace

BlockEvaluator::Scratch::Level& BlockEvaluator::Scratch::level(size_t depth) {
  while (levels_.size() <= depth) levels_.push_back(std::make_unique<Level>());
  return *levels_[depth];
}

BlockEvaluator::BlockEvaluator(const ir::Scene& scene, double time, bool prune)
    : scene_(scene), time_(time), point_(scene, time) {
  if (prune) prune_ = buildPruneGrid(scene);
}

void BlockEvaluator::at(const PointBlock& points, BlockResult& out, Scratch& scratch) const {
  if (!scene_.root) {
    for (int i = 0; i < points.count; ++i) out.distance[i] = std::numeric_limits<double>::infinity();
    std::fill(out.material, out.material + points.count, -1);
    return;
  }
  if (prune_) {
    atPruned(points, out, scratch);
    return;
  }
  evalNode(*scene_.root, points, -1, out, scratch, 0);
}

// The points grouped by their cell's mask; each group evaluates the union of
// the parts listed there, in the union's order and with its rule (the first
// strictly nearer part's material). A part left out is farther than a listed
// one everywhere in the cell, so the value and material are the whole union's.
void BlockEvaluator::atPruned(const PointBlock& points, BlockResult& out, Scratch& scratch) const {
  const ir::PruneGrid& g = *prune_;
  const int count = points.count;
  std::array<std::array<std::uint32_t, 4>, kEvalBlock> masks;
  std::array<int, kEvalBlock> order;
  for (int i = 0; i < count; ++i) {
    masks[i] = pruneMaskAt(g, points.at(i));
    order[i] = i;
  }
  std::stable_sort(order.begin(), order.begin() + count, [&](int a, int b) { return masks[a] < masks[b]; });
  const int root_material = scene_.root->material;
  PointBlock group;
  BlockResult best, r;
  for (int begin = 0; begin < count;) {
    int end = begin + 1;
    while (end < count && masks[order[end]] == masks[order[begin]]) ++end;
    const std::array<std::uint32_t, 4>& mask = masks[order[begin]];
    group.count = end - begin;
    for (int k = begin; k < end; ++k) group.set(k - begin, points.at(order[k]));
    bool first = true;
    for (size_t i = 0; i < g.parts.size(); ++i) {
      if (!g.lists(mask, i)) continue;
      const int inherited = g.inherited[i] >= 0 ? g.inherited[i] : root_material;
      evalNode(*g.parts[i], group, inherited, first ? best : r, scratch, 0);
      if (!first)
        for (int k = 0; k < group.count; ++k) {
          best.material[k] = r.distance[k] < best.distance[k] ? r.material[k] : best.material[k];
          best.distance[k] = std::min(best.distance[k], r.distance[k]);
        }
      first = false;
    }
    for (int k = begin; k < end; ++k) {
      out.distance[order[k]] = best.distance[k - begin];
      out.material[order[k]] = best.material[k - begin];
    }
    begin = end;
  }
}

void BlockEvaluator::evaluate(const double* xyz, size_t n, double* distance, int* material,
                              Scratch& scratch) const {
  PointBlock points;
  BlockResult r;
  for (size_t begin = 0; begin < n; begin += kEvalBlock) {
    points.count = int(std::min<size_t>(kEvalBlock, n - begin));
    for (int i = 0; i < points.count; ++i) {
      const double* q = xyz + 3 * (begin + i);
      points.x[i] = q[0];
      points.y[i] = q[1];
      points.z[i] = q[2];
    }
    at(points, r, scratch);
    if (distance) std::copy(r.distance, r.distance + points.count, distance + begin);
    if (material) std::copy(r.material, r.material + points.count, material + begin);
  }
}

void BlockEvaluator::gradient(const double* xyz, size_t n, double* g, Scratch& scratch, double h) const {
  PointBlock plus, minus;
  BlockResult rp, rm;
  for (size_t begin = 0; begin < n; begin += kEvalBlock) {
    const int count = int(std::min<size_t>(kEvalBlock, n - begin));
    plus.count = minus.count = count;
    for (int a = 0; a < 3; ++a) {
      dvec3 e(0);
      e[a] = h;
      // p + e and p - e on every axis, as Evaluator::gradient (adding the
      // zeros too: -0 + 0 is +0).
      for (int i = 0; i < count; ++i) {
        const double* q = xyz + 3 * (begin + i);
        const dvec3 p(q[0], q[1], q[2]);
        plus.set(i, p + e);
        minus.set(i, p - e);
      }
      at(plus, rp, scratch);
      at(minus, rm, scratch);
      for (int i = 0; i < count; ++i) g[3 * (begin + i) + a] = (rp.distance[i] - rm.distance[i]) / (2 * h);
    }
  }
}

// Each case is the per-point Evaluator::evalNode's, its per-point work a loop
// over the block. A node kind without a case here is evaluated point by point.
// Built twice, as the primitives' loops are (shapes/primitives.cpp).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
__attribute__((target_clones("default", "arch=x86-64-v3")))
#endif
void BlockEvaluator::evalNode(const ir::Node& n, const PointBlock& p, int inherited, BlockResult& out,
                              Scratch& scratch, size_t depth) const {
  const int mat = n.material >= 0 ? n.material : inherited;
  const double t = time_;
  const int count = p.count;
  Scratch::Level& level = scratch.level(depth);
  PointBlock& q = level.points;  // the child's points, where they differ from p
  q.count = count;
  auto child = [&](size_t i, const PointBlock& at, BlockResult& r) {
    evalNode(*n.children[i], at, mat, r, scratch, depth + 1);
  };
  auto fillMaterial = [&] { std::fill(out.material, out.material + count, mat); };
  switch (n.kind) {
    case ir::NodeKind::Primitive: {
      if (n.primitive == PrimitiveKind::Polygon) {
        for (int i = 0; i < count; ++i) out.distance[i] = polygonDistance(n.points, glm::dvec2(p.x[i], p.y[i]));
      } else {
        std::array<double, kMaxPrimitiveArgs> args{};
        for (size_t i = 0; i < n.args.size(); ++i) args[i] = n.args[i].at(t);
        blockDistance(n.primitive)(args.data(), p.x, p.y, p.z, out.distance, count);
      }
      fillMaterial();
      return;
    }
    case ir::NodeKind::Mesh:
      for (int i = 0; i < count; ++i) out.distance[i] = n.mesh->distance->signedDistance(p.at(i));
      fillMaterial();
      return;
    case ir::NodeKind::Union:
    case ir::NodeKind::Intersect: {
      const double k = n.smooth.at(t);
      const bool is_union = n.kind == ir::NodeKind::Union;
      child(0, p, out);
      BlockResult& r = level.result;
      for (size_t c = 1; c < n.children.size(); ++c) {
        child(c, p, r);
        // Selects, not branches, and the blend's k <= 0 case hoisted: loops
        // the compiler vectorises.
        if (is_union) {
          for (int i = 0; i < count; ++i)
            out.material[i] = r.distance[i] < out.distance[i] ? r.material[i] : out.material[i];
          if (k <= 0) {
            for (int i = 0; i < count; ++i) out.distance[i] = std::min(out.distance[i], r.distance[i]);
          } else {
            for (int i = 0; i < count; ++i) out.distance[i] = blendMin(out.distance[i], r.distance[i], k);
          }
        } else {
          for (int i = 0; i < count; ++i)
            out.material[i] = r.distance[i] > out.distance[i] ? r.material[i] : out.material[i];
          if (k <= 0) {
            for (int i = 0; i < count; ++i) out.distance[i] = -std::min(-out.distance[i], -r.distance[i]);
          } else {
            for (int i = 0; i < count; ++i) out.distance[i] = blendMax(out.distance[i], r.distance[i], k);
          }
        }
      }
      return;
    }
    case ir::NodeKind::Subtract: {
      const double k = n.smooth.at(t);
      child(0, p, out);
      BlockResult& r = level.result;
      for (size_t c = 1; c < n.children.size(); ++c) {
        child(c, p, r);
        if (k <= 0) {
          for (int i = 0; i < count; ++i) out.distance[i] = -std::min(-out.distance[i], r.distance[i]);  // blendMax(a, -r, 0)
        } else {
          for (int i = 0; i < count; ++i) out.distance[i] = blendMax(out.distance[i], -r.distance[i], k);
        }
      }
      return;
    }
    case ir::NodeKind::Translate: {
      const dvec3 o = n.vec.at(t);
      for (int i = 0; i < count; ++i) q.set(i, p.at(i) - o);
      child(0, q, out);
      return;
    }
    case ir::NodeKind::Rotate: {
      const glm::dmat3 m = glm::transpose(rotationMatrix(n.vec.value(), n.amount.at(t)));
      for (int i = 0; i < count; ++i) q.set(i, m * p.at(i));
      child(0, q, out);
      return;
    }
    case ir::NodeKind::Scale: {
      const double s = n.amount.at(t);
      for (int i = 0; i < count; ++i) q.set(i, p.at(i) / s);
      child(0, q, out);
      for (int i = 0; i < count; ++i) out.distance[i] *= s;
      return;
    }
    case ir::NodeKind::ScaleNonUniform: {
      const dvec3 s = n.vec.at(t);
      for (int i = 0; i < count; ++i) q.set(i, p.at(i) / s);
      child(0, q, out);
      const double f = std::min(s.x, std::min(s.y, s.z));
      for (int i = 0; i < count; ++i) out.distance[i] *= f;
      return;
    }
    case ir::NodeKind::Affine: {
      for (int i = 0; i < count; ++i) q.set(i, n.linear * p.at(i) + n.offset);
      child(0, q, out);
      for (int i = 0; i < count; ++i) out.distance[i] *= n.scale;
      return;
    }
    case ir::NodeKind::Reflect: {
      const dvec3 nn = n.vec.value();
      for (int i = 0; i < count; ++i) {
        const dvec3 x = p.at(i);
        const double side = glm::dot(x, nn) - n.amount.value;
        q.set(i, side < 0 ? x - 2 * side * nn : x);
      }
      child(0, q, out);
      return;
    }
    case ir::NodeKind::Repeat: {
      const dvec3 cell = n.vec.value();
      int span[3] = {0, 0, 0};
      double half[3] = {0, 0, 0}, centre[3] = {0, 0, 0};
      for (int a = 0; a < 3; ++a) {
        if (cell[a] == 0) continue;
        const RepeatCells r = repeatCells(n, a);
        span[a] = r.side;
        centre[a] = r.centre;
        if (n.count[a] > 0) half[a] = (n.count[a] - 1) * 0.5;
      }
      // The cell index of every point, per axis; then each neighbour offset
      // is one pass over the block.
      PointBlock& index = level.extra;
      index.count = count;
      for (int i = 0; i < count; ++i) {
        const dvec3 x = p.at(i);
        dvec3 j(0);
        for (int a = 0; a < 3; ++a)
          if (cell[a] != 0) j[a] = repeatCellIndex(x[a] - centre[a], cell[a], n.count[a]);
        index.set(i, j);
      }
      BlockResult& r = level.result;
      for (int i = 0; i < count; ++i) {
        out.distance[i] = std::numeric_limits<double>::infinity();
        out.material[i] = mat;
      }
      for (int dx = -span[0]; dx <= span[0]; ++dx)
        for (int dy = -span[1]; dy <= span[1]; ++dy)
          for (int dz = -span[2]; dz <= span[2]; ++dz) {
            const int d[3] = {dx, dy, dz};
            for (int i = 0; i < count; ++i) {
              dvec3 x = p.at(i);
              const dvec3 idx = index.at(i);
              for (int a = 0; a < 3; ++a) {
                if (cell[a] == 0) continue;
                double j = idx[a] + d[a];
                if (n.count[a] > 0) j = std::clamp(j, -half[a], half[a]);
                x[a] = p.at(i)[a] - cell[a] * j;
              }
              q.set(i, x);
            }
            child(0, q, r);
            for (int i = 0; i < count; ++i) {
              const bool nearer = r.distance[i] < out.distance[i];
              out.distance[i] = nearer ? r.distance[i] : out.distance[i];
              out.material[i] = nearer ? r.material[i] : out.material[i];
            }
          }
      return;
    }
    case ir::NodeKind::Elongate: {
      const dvec3 h = n.vec.at(t);
      for (int i = 0; i < count; ++i) {
        const dvec3 x = p.at(i);
        q.set(i, x - glm::clamp(x, -h, h));
      }
      child(0, q, out);
      return;
    }
    case ir::NodeKind::Round: {
      const double r = n.amount.at(t);
      child(0, p, out);
      for (int i = 0; i < count; ++i) out.distance[i] -= r;
      return;
    }
    case ir::NodeKind::Shell: {
      const double r = n.amount.at(t);
      child(0, p, out);
      for (int i = 0; i < count; ++i) out.distance[i] = std::fabs(out.distance[i]) - r;
      return;
    }
    case ir::NodeKind::Extrude: {
      const double h = n.amount.at(t);
      for (int i = 0; i < count; ++i) q.set(i, dvec3(p.x[i], p.y[i], 0));
      child(0, q, out);
      for (int i = 0; i < count; ++i) {
        const glm::dvec2 w(out.distance[i], std::fabs(p.z[i]) - h);
        out.distance[i] = std::min(std::max(w.x, w.y), 0.0) + glm::length(glm::max(w, glm::dvec2(0)));
      }
      return;
    }
    case ir::NodeKind::Twist: {
      // The child at every point, then the cylinder's distance outside its
      // reach (passes/deform.h), as the per-point evaluator.
      const double amount = n.amount.at(t);
      for (int i = 0; i < count; ++i) {
        const dvec3 x = p.at(i);
        q.set(i, glm::transpose(rotationMatrix(dvec3(0, 1, 0), amount * x.y)) * x);
      }
      child(0, q, out);
      for (int i = 0; i < count; ++i) {
        const dvec3 x = p.at(i);
        if (!deformedAt(n, x)) {
          out.distance[i] = deformOutside(n, x);
          out.material[i] = mat;
        } else {
          out.distance[i] /= n.deform_lipschitz;
        }
      }
      return;
    }
    case ir::NodeKind::Revolve: {
      const double o = n.amount.at(t);
      for (int i = 0; i < count; ++i) q.set(i, dvec3(std::sqrt(p.x[i] * p.x[i] + p.z[i] * p.z[i]) - o, p.y[i], 0));
      if (n.lathe) {
        // As the per-point evaluator: the polygon without its edges on the axis.
        const ir::Node& c = *n.children[0];
        for (int i = 0; i < count; ++i) {
          out.distance[i] = polygonDistance(c.points, glm::dvec2(q.x[i], q.y[i]), -n.amount.value);
          out.material[i] = c.material >= 0 ? c.material : mat;
        }
        return;
      }
      child(0, q, out);
      return;
    }
    case ir::NodeKind::Morph: {
      const double w = n.amount.at(t);
      BlockResult& b = level.result;
      child(0, p, out);
      child(1, p, b);
      for (int i = 0; i < count; ++i) {
        out.distance[i] = w * out.distance[i] + (1 - w) * b.distance[i];
        if (!(w >= 0.5)) out.material[i] = b.material[i];
      }
      return;
    }
    default:
      // Instances: the branch and bound visits instances nearest first, an
      // order (and so a smooth blend's rounding) that is the point's own.
      for (int i = 0; i < count; ++i) {
        const EvalResult r = point_.evalNode(n, p.at(i), inherited);
        out.distance[i] = r.distance;
        out.material[i] = r.material;
      }
      return;
  }
}

}  // namespace sdfc
