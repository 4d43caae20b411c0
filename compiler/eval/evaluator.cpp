#include "eval/evaluator.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "eval/noise.h"
#include "passes/deform.h"
#include "passes/passes.h"

namespace sdfc {

using glm::dvec3;

double smoothMin(double a, double b, double k) {
  if (k <= 0) return std::min(a, b);
  const double h = std::max(k - std::fabs(a - b), 0.0) / k;
  return std::min(a, b) - h * h * k * 0.25;
}

double smoothMax(double a, double b, double k) { return -smoothMin(-a, -b, k); }

dvec3 twistPoint(const dvec3& p, double degrees_per_unit) {
  return glm::transpose(rotationMatrix(dvec3(0, 1, 0), degrees_per_unit * p.y)) * p;
}

dvec3 bendPoint(const dvec3& p, double degrees_per_unit) {
  const double a = glm::radians(degrees_per_unit * p.x), c = std::cos(a), s = std::sin(a);
  return {c * p.x - s * p.z, p.y, s * p.x + c * p.z};
}

dvec3 polarPoint(const dvec3& p, double radians) {
  const double c = std::cos(radians), s = std::sin(radians);
  return {c * p.x + s * p.z, p.y, c * p.z - s * p.x};
}

double repeatCellIndex(double x, double cell, int count) {
  if (count == 0) return std::round(x / cell);
  const double half = (count - 1) * 0.5;
  return std::clamp(std::round(x / cell + half), 0.0, static_cast<double>(count - 1)) - half;
}

EvalResult Evaluator::at(const dvec3& p) const {
  if (!scene_.root) return {std::numeric_limits<double>::infinity(), -1};
  return evalNode(*scene_.root, p, -1);
}

dvec3 Evaluator::gradient(const dvec3& p, double h) const {
  dvec3 g;
  for (int a = 0; a < 3; ++a) {
    dvec3 e(0);
    e[a] = h;
    g[a] = (distance(p + e) - distance(p - e)) / (2 * h);
  }
  return g;
}

EvalResult Evaluator::evalInstance(const ir::Node& n, size_t i, const dvec3& p, int inherited) const {
  const ir::InstanceSet& set = *n.instances;
  const ir::Instance& inst = set.instances[i];
  const int mat = inst.material >= 0 ? inst.material : inherited;
  dvec3 q = p + inst.offset;
  double scale = 1;
  if (inst.transform >= 0) {
    q = set.transforms[inst.transform].linear * p + inst.offset;
    scale = set.transforms[inst.transform].scale;
  }
  const ir::Node& templ = *n.children[inst.templ];
  EvalResult r;
  if (ir::takesParams(set, templ)) {
    r = {primitiveInfo(templ.primitive).distance(set.paramsOf(i), q), mat};
  } else {
    r = evalNode(templ, q, mat);
  }
  r.distance *= scale;
  return r;
}

// Nearest first, branch and bound: a box's distance is a lower bound on every
// instance inside it, so a box no nearer than the best so far (plus the blend
// radius, beyond which a smooth minimum adds nothing) is skipped.
EvalResult Evaluator::evalInstances(const ir::Node& n, const dvec3& p, int inherited) const {
  const ir::InstanceSet& set = *n.instances;
  const double k = std::max(n.smooth.at(time_), 0.0);
  EvalResult best{std::numeric_limits<double>::infinity(), inherited};
  if (set.nodes.empty()) return best;
  if (set.grid.blend) return evalBlend(n, p, inherited, k);
  struct Entry {
    std::uint32_t node;
    double distance;
  };
  std::vector<Entry> stack;
  stack.reserve(2 * set.depth + 2);
  stack.push_back({0, set.nodes[0].box.signedDistance(p)});
  while (!stack.empty()) {
    const Entry e = stack.back();
    stack.pop_back();
    if (e.distance >= best.distance + k) continue;
    const ir::BvhNode& node = set.nodes[e.node];
    if (node.count == 0) {
      const std::uint32_t l = e.node + 1, r = node.first;
      const double dl = set.nodes[l].box.signedDistance(p), dr = set.nodes[r].box.signedDistance(p);
      // On a tie the left child first, as the kernel does.
      if (dl <= dr) {
        stack.push_back({r, dr});
        stack.push_back({l, dl});
      } else {
        stack.push_back({l, dl});
        stack.push_back({r, dr});
      }
      continue;
    }
    for (std::uint32_t i = node.first; i < node.first + node.count; ++i) {
      const EvalResult r = evalInstance(n, i, p, inherited);
      if (k > 0) {
        const double blended = smoothMin(best.distance, r.distance, k);
        if (r.distance < best.distance) best.material = r.material;
        best.distance = blended;
      } else if (r.distance < best.distance) {
        best = r;
      }
    }
  }
  return best;
}

// A smooth set with a blend grid (passes/blend_grid.cpp): the members'
// smooth minimum taken nearest first, over those within k of the nearest (the
// rest change nothing). In a cell those are among its list; outside the grid
// any member may be. Equal values keep the list's order, as the kernel does.
EvalResult Evaluator::evalBlend(const ir::Node& n, const dvec3& p, int inherited, double k) const {
  const ir::InstanceSet& set = *n.instances;
  const ir::InstanceGrid& g = set.grid;
  std::vector<std::pair<double, EvalResult>> near;
  double m = std::numeric_limits<double>::infinity();
  auto take = [&](size_t i) {
    const EvalResult r = evalInstance(n, i, p, inherited);
    near.push_back({r.distance, r});
    m = std::min(m, r.distance);
  };
  const dvec3 hi = g.lo + dvec3(g.dims) * g.cell;
  bool listed = false;
  if (glm::all(glm::greaterThanEqual(p, g.lo)) && glm::all(glm::lessThanEqual(p, hi))) {
    const ir::GridCellAt at = instanceGridCellAt(g, p);
    for (std::int32_t j = 0; j < g.count[at.index]; ++j) take(g.entries[g.first[at.index] + j]);
    listed = g.count[at.index] > 0;
  }
  if (!listed) {
    // Far from the parts: the nearest by the hierarchy (branch and bound),
    // then every member whose box lies within k of it.
    std::vector<std::uint32_t> stack{0};
    while (!stack.empty()) {
      const ir::BvhNode& node = set.nodes[stack.back()];
      const std::uint32_t ni = stack.back();
      stack.pop_back();
      if (node.box.signedDistance(p) >= m + k) continue;
      if (node.count == 0) {
        stack.push_back(node.first);
        stack.push_back(ni + 1);
        continue;
      }
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i) take(i);
    }
  }
  std::stable_sort(near.begin(), near.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  EvalResult best{std::numeric_limits<double>::infinity(), inherited};
  for (const auto& [v, r] : near) {
    if (v >= m + k) break;
    if (v < best.distance) best.material = r.material;
    best.distance = smoothMin(best.distance, v, k);
  }
  return best;
}

EvalResult Evaluator::evalNode(const ir::Node& n, const dvec3& p, int inherited) const {
  const int mat = n.material >= 0 ? n.material : inherited;
  const double t = time_;
  auto child = [&](size_t i, const dvec3& q) { return evalNode(*n.children[i], q, mat); };
  switch (n.kind) {
    case ir::NodeKind::Primitive: {
      if (n.primitive == PrimitiveKind::Polygon) return {polygonDistance(n.points, glm::dvec2(p.x, p.y)), mat};
      // A fixed array: this runs for every primitive at every point (the mesher
      // spent a fifth of its time in malloc when it was a vector).
      std::array<double, kMaxPrimitiveArgs> args{};
      for (size_t i = 0; i < n.args.size(); ++i) args[i] = n.args[i].at(t);
      return {primitiveInfo(n.primitive).distance(args.data(), p), mat};
    }
    case ir::NodeKind::Mesh: return {n.mesh->distance->signedDistance(p), mat};
    case ir::NodeKind::Union: {
      const double k = n.smooth.at(t);
      EvalResult best = child(0, p);
      for (size_t i = 1; i < n.children.size(); ++i) {
        EvalResult r = child(i, p);
        const double blended = smoothMin(best.distance, r.distance, k);
        if (r.distance < best.distance) best.material = r.material;
        best.distance = blended;
      }
      return best;
    }
    case ir::NodeKind::Intersect: {
      const double k = n.smooth.at(t);
      EvalResult best = child(0, p);
      for (size_t i = 1; i < n.children.size(); ++i) {
        EvalResult r = child(i, p);
        const double blended = smoothMax(best.distance, r.distance, k);
        if (r.distance > best.distance) best.material = r.material;
        best.distance = blended;
      }
      return best;
    }
    case ir::NodeKind::Subtract: {
      // The cut faces show the material of the shape being carved.
      const double k = n.smooth.at(t);
      EvalResult a = child(0, p);
      for (size_t i = 1; i < n.children.size(); ++i)
        a.distance = smoothMax(a.distance, -child(i, p).distance, k);
      return a;
    }
    case ir::NodeKind::Translate: return child(0, p - n.vec.at(t));
    case ir::NodeKind::Rotate:
      return child(0, glm::transpose(rotationMatrix(n.vec.value(), n.amount.at(t))) * p);
    case ir::NodeKind::Scale: {
      const double s = n.amount.at(t);
      EvalResult r = child(0, p / s);
      r.distance *= s;
      return r;
    }
    case ir::NodeKind::ScaleNonUniform: {
      const dvec3 s = n.vec.at(t);
      EvalResult r = child(0, p / s);
      r.distance *= std::min(s.x, std::min(s.y, s.z));
      return r;
    }
    case ir::NodeKind::Affine: {
      EvalResult r = child(0, n.linear * p + n.offset);
      r.distance *= n.scale;
      return r;
    }
    case ir::NodeKind::Reflect: {
      const dvec3 nn = n.vec.value();
      const double side = glm::dot(p, nn) - n.amount.value;
      return child(0, side < 0 ? p - 2 * side * nn : p);
    }
    case ir::NodeKind::Repeat: {
      // The copy whose centre is nearest, and the ones on either side that
      // can hold the nearest point (repeatCells, passes.h).
      const dvec3 cell = n.vec.value();
      dvec3 index(0);
      int span[3] = {0, 0, 0};
      for (int a = 0; a < 3; ++a) {
        if (cell[a] == 0) continue;
        const RepeatCells r = repeatCells(n, a);
        index[a] = repeatCellIndex(p[a] - r.centre, cell[a], n.count[a]);
        span[a] = r.side;
      }
      EvalResult best{std::numeric_limits<double>::infinity(), mat};
      for (int dx = -span[0]; dx <= span[0]; ++dx)
        for (int dy = -span[1]; dy <= span[1]; ++dy)
          for (int dz = -span[2]; dz <= span[2]; ++dz) {
            dvec3 q = p;
            const int d[3] = {dx, dy, dz};
            for (int a = 0; a < 3; ++a) {
              if (cell[a] == 0) continue;
              double j = index[a] + d[a];
              if (n.count[a] > 0) {
                const double half = (n.count[a] - 1) * 0.5;
                j = std::clamp(j, -half, half);
              }
              q[a] = p[a] - cell[a] * j;
            }
            EvalResult e = child(0, q);
            if (e.distance < best.distance) best = e;
          }
      return best;
    }
    case ir::NodeKind::Elongate: {
      const dvec3 h = n.vec.at(t);
      return child(0, p - glm::clamp(p, -h, h));
    }
    case ir::NodeKind::Instances: return evalInstances(n, p, mat);
    case ir::NodeKind::Round: {
      EvalResult r = child(0, p);
      r.distance -= n.amount.at(t);
      return r;
    }
    case ir::NodeKind::Shell: {
      EvalResult r = child(0, p);
      r.distance = std::fabs(r.distance) - n.amount.at(t);
      return r;
    }
    case ir::NodeKind::Extrude: {
      // The profile's distance and the slab's, combined as a 2D box corner
      // (exact for an exact profile: the nearest point is on a face, an
      // edge of the rim, or inside).
      EvalResult r = child(0, dvec3(p.x, p.y, 0));
      const glm::dvec2 w(r.distance, std::fabs(p.z) - n.amount.at(t));
      r.distance = std::min(std::max(w.x, w.y), 0.0) + glm::length(glm::max(w, glm::dvec2(0)));
      return r;
    }
    case ir::NodeKind::Twist:
    case ir::NodeKind::Bend: {
      // Within the radius R that holds the child (and a boxed bend's box),
      // the deformed field divided by its Lipschitz factor; outside, the
      // distance to that cylinder (and box): passes/deform.h.
      if (!deformedAt(n, p)) return {deformOutside(n, p), mat};
      EvalResult e = child(0, n.kind == ir::NodeKind::Twist ? twistPoint(p, n.amount.at(t)) : bendPoint(p, n.amount.at(t)));
      e.distance /= n.deform_lipschitz;
      return e;
    }
    case ir::NodeKind::Displace: {
      // The displaced field over its stretch, and outside the box that holds
      // the displaced shape (its own bounds) no less than the distance to
      // that box: both are lower bounds on the distance there, the box's
      // 1-Lipschitz and not divided (docs/language.md, displace).
      EvalResult e = child(0, p);
      e.distance = (e.distance + n.amount.at(t) * fractalNoise(p * n.vec.x.at(t), n.count.x)) / n.deform_lipschitz;
      if (n.bounds.finite()) {
        const double box = glm::length(glm::max(glm::abs(p - n.bounds.center()) - n.bounds.halfSize(), dvec3(0)));
        if (box > 0) e.distance = std::max(e.distance, box);
      }
      return e;
    }
    case ir::NodeKind::RepeatPolar: {
      const int count = n.count.x;
      if (count == 1) return child(0, p);
      // The sector whose copy is nearest in angle and those polarSectors()
      // adds (passes.h).
      const PolarSectors s = polarSectors(n);
      const double w = 2 * M_PI / count, i = std::round(std::remainder(std::atan2(p.z, p.x) - s.centre, 2 * M_PI) / w);
      EvalResult best{std::numeric_limits<double>::infinity(), mat};
      for (int d = s.first; d <= s.last; ++d) {
        EvalResult e = child(0, polarPoint(p, (i + d) * w));
        if (e.distance < best.distance) best = e;
      }
      return best;
    }
    case ir::NodeKind::Revolve: {
      const dvec3 q(std::sqrt(p.x * p.x + p.z * p.z) - n.amount.at(t), p.y, 0);
      const ir::Node& c = *n.children[0];
      if (n.lathe) return {polygonDistance(c.points, glm::dvec2(q.x, q.y), -n.amount.value), c.material >= 0 ? c.material : mat};
      return child(0, q);
    }
    case ir::NodeKind::Morph: {
      const double w = n.amount.at(t);
      EvalResult a = child(0, p), b = child(1, p);
      return {w * a.distance + (1 - w) * b.distance, w >= 0.5 ? a.material : b.material};
    }
  }
  return {std::numeric_limits<double>::infinity(), mat};
}

}  // namespace sdfc
