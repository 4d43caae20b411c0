#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdio>
#include <unordered_set>

#include "eval/evaluator.h"
#include "eval/noise.h"
#include "passes/deform.h"
#include "passes/passes.h"

namespace sdfc {
namespace {

using glm::dvec3;
constexpr double kInf = std::numeric_limits<double>::infinity();

// Largest value a parameter takes over all times (sizes grow with it).
double upper(const ir::Scalar& s) {
  const ir::Interval r = s.range();
  return r.bounded() ? r.hi : kInf;
}

// bend's Lipschitz factor within radius R of the y axis, k in radians per
// unit. The child is read at q = R_y(k x) p, whose Jacobian is
// R (I + k (-z, 0, x) e_x^T): in the (x, z) plane [[1 - k z, 0], [k x, 1]],
// y untouched. Its largest singular value is convex in (x, z) (a norm of an
// affine map), so over the disc x^2 + z^2 <= R^2 it peaks on the rim; sampled
// there, plus the most it can rise between samples (the entries move k times
// as fast as the point, a norm no faster): R k pi / samples.
double bendStretchAt(double k, double x, double z) {
  const double a = 1 - k * z, b = k * x;
  const double t = a * a + b * b + 1;
  return std::sqrt((t + std::sqrt(std::max(t * t - 4 * a * a, 0.0))) / 2);
}

double bendLipschitz(double k, double radius) {
  constexpr int kSamples = 720;
  double best = 1;
  for (int i = 0; i < kSamples; ++i) {
    const double phi = 2 * M_PI * i / kSamples;
    best = std::max(best, bendStretchAt(k, radius * std::cos(phi), radius * std::sin(phi)));
  }
  return best + k * radius * M_PI / kSamples;
}

// The same over the part of that disc inside a rectangle of x, z (a box's),
// for every rate in `rate` (radians per unit). The stretch is convex in the
// point and in the rate, so it peaks at the region's extreme points, at the
// least or most rate: the rectangle's corners inside the disc, and the rim's
// points inside the rectangle, sampled as bendLipschitz does (each rim point
// inside lies within half a sample's spacing of a sample inside the
// rectangle grown by that much).
double boxedBendLipschitz(ir::Interval rate, const Aabb& rectangle, double radius) {
  constexpr int kSamples = 720;
  const double k = std::max(std::fabs(rate.lo), std::fabs(rate.hi)), slack = M_PI * radius / kSamples;
  double best = 1;
  for (const double r : {rate.lo, rate.hi}) {
    for (const double x : {rectangle.lo.x, rectangle.hi.x})
      for (const double z : {rectangle.lo.z, rectangle.hi.z})
        if (x * x + z * z <= radius * radius) best = std::max(best, bendStretchAt(r, x, z));
    for (int i = 0; i < kSamples; ++i) {
      const double phi = 2 * M_PI * i / kSamples, x = radius * std::cos(phi), z = radius * std::sin(phi);
      if (x >= rectangle.lo.x - slack && x <= rectangle.hi.x + slack && z >= rectangle.lo.z - slack &&
          z <= rectangle.hi.z + slack)
        best = std::max(best, bendStretchAt(r, x, z));
    }
  }
  return best + k * radius * M_PI / kSamples;
}

// cos and sin over an interval of angles.
ir::Interval cosOver(double lo, double hi) {
  if (hi - lo >= 2 * M_PI) return {-1, 1};
  ir::Interval r{std::min(std::cos(lo), std::cos(hi)), std::max(std::cos(lo), std::cos(hi))};
  for (double c = std::ceil(lo / M_PI) * M_PI; c <= hi; c += M_PI) {
    const double v = std::cos(c);
    r = {std::min(r.lo, v), std::max(r.hi, v)};
  }
  return r;
}
ir::Interval sinOver(double lo, double hi) { return cosOver(lo - M_PI / 2, hi - M_PI / 2); }

// The box that bend(rate) bends the child's box b into, within radius R of
// the y axis: p = R_y(-a) q with a = k p.x (k over `rate`, radians per
// unit). Cut p.x into slabs; in each, a lies in k times the slab, so
// p.x = cos(a) q.x + sin(a) q.z and p.z = -sin(a) q.x + cos(a) q.z lie in
// their interval products over q in b, and a slab whose p.x interval misses
// it holds no point of the bent box.
Aabb bentBounds(const Aabb& b, ir::Interval rate, double radius) {
  constexpr int kSlabs = 512;
  const ir::Interval qx{b.lo.x, b.hi.x}, qz{b.lo.z, b.hi.z};
  Aabb held;
  for (int i = 0; i < kSlabs; ++i) {
    const double x0 = -radius + 2 * radius * i / kSlabs, x1 = -radius + 2 * radius * (i + 1) / kSlabs;
    const ir::Interval a = ir::multiply({x0, x1}, rate);
    const ir::Interval c = cosOver(a.lo, a.hi), s = sinOver(a.lo, a.hi);
    const ir::Interval sx = ir::multiply(c, qx), tx = ir::multiply(s, qz);
    const ir::Interval px{sx.lo + tx.lo, sx.hi + tx.hi};
    if (px.hi < x0 || px.lo > x1) continue;
    const ir::Interval sz = ir::multiply(s, qx), tz = ir::multiply(c, qz);
    const ir::Interval pz{tz.lo - sz.hi, tz.hi - sz.lo};
    held = held.unite({glm::dvec3(std::max(x0, px.lo), b.lo.y, pz.lo), glm::dvec3(std::min(x1, px.hi), b.hi.y, pz.hi)});
  }
  // Rounding in the products: a hair more.
  return held.empty() ? held : held.grow(1e-9 * (1 + radius));
}

class Analyzer {
 public:
  Analyzer(const ir::Scene& scene, Diagnostics& diags) : scene_(scene), diags_(diags) {}

  // The grid of set n, for its ir::Node::lowered (built with a smaller one).
  void rebuildGrid(ir::Node& n) {
    ir::InstanceSet& set = *n.instances;
    if (set.nodes.empty() || set.size() == 0) return;
    set.grid = ir::InstanceGrid{};
    buildGrid(n);
  }

  void visit(ir::Node& n) {
    if (!done_.insert(&n).second) return;
    for (const ir::NodeRef& c : n.children) visit(*c);
    n.exact = true;
    n.lipschitz = 1;
    n.cost = 0;
    for (const ir::NodeRef& c : n.children) {
      n.exact = n.exact && c->exact;
      n.lipschitz = std::max(n.lipschitz, c->lipschitz);
      n.cost += c->cost;
    }
    const ir::Node* first = n.children.empty() ? nullptr : n.children[0].get();
    switch (n.kind) {
      case ir::NodeKind::Primitive: primitive(n); break;
      case ir::NodeKind::Union:
      case ir::NodeKind::Intersect:
      case ir::NodeKind::Subtract: csg(n); break;
      case ir::NodeKind::Translate: {
        const ir::Interval x = n.vec.x.range(), y = n.vec.y.range(), z = n.vec.z.range();
        if (!first->bounds.finite() || !x.bounded() || !y.bounded() || !z.bounded()) {
          n.bounds = Aabb::infinite();
        } else {
          n.bounds = {first->bounds.lo + dvec3(x.lo, y.lo, z.lo), first->bounds.hi + dvec3(x.hi, y.hi, z.hi)};
        }
        n.cost += 0.2;
        break;
      }
      case ir::NodeKind::Rotate: {
        // A constant angle: the rotated box (repeat reads whether it is off
        // its cell's centre). Time-varying: any rotation about the axis; a sphere.
        if (!first->bounds.finite()) {
          n.bounds = Aabb::infinite();
        } else if (n.amount.isConst()) {
          n.bounds = transformBox(first->bounds, rotationMatrix(n.vec.value(), n.amount.value), dvec3(0));
        } else {
          const double r = std::max(glm::length(first->bounds.lo), glm::length(first->bounds.hi));
          n.bounds = Aabb{dvec3(-r), dvec3(r)};
        }
        n.cost += 0.5;
        break;
      }
      case ir::NodeKind::Scale: {
        const double s = upper(n.amount);
        n.bounds = std::isfinite(s) && first->bounds.finite()
                       ? Aabb{first->bounds.lo * s, first->bounds.hi * s}
                       : Aabb::infinite();
        n.cost += 0.2;
        break;
      }
      case ir::NodeKind::ScaleNonUniform: {
        const dvec3 s(upper(n.vec.x), upper(n.vec.y), upper(n.vec.z));
        n.bounds = first->bounds.finite() ? Aabb{first->bounds.lo * s, first->bounds.hi * s}
                                          : Aabb::infinite();
        n.exact = false;
        n.cost += 0.3;
        break;
      }
      case ir::NodeKind::Affine: {
        // local = A p + b  =>  p = A^-1 (local - b)
        const glm::dmat3 inv = glm::inverse(n.linear);
        n.bounds = transformBox(first->bounds, inv, -(inv * n.offset));
        n.cost += 0.3;
        break;
      }
      case ir::NodeKind::Reflect: {
        const dvec3 nn = n.vec.value();
        const double o = n.amount.value;
        const glm::dmat3 householder = glm::dmat3(1.0) - 2.0 * glm::outerProduct(nn, nn);
        const Aabb mirrored = transformBox(first->bounds, householder, 2.0 * o * nn);
        n.bounds = first->bounds.unite(mirrored);
        // Exact only when the child lies wholly in front of the plane.
        if (first->bounds.finite()) {
          double lowest = kInf;
          for (int i = 0; i < 8; ++i) {
            const Aabb& b = first->bounds;
            const dvec3 c((i & 1) ? b.hi.x : b.lo.x, (i & 2) ? b.hi.y : b.lo.y, (i & 4) ? b.hi.z : b.lo.z);
            lowest = std::min(lowest, glm::dot(c, nn) - o);
          }
          if (lowest < -1e-12) n.exact = false;
        } else {
          n.exact = false;
        }
        n.cost += 0.3;
        break;
      }
      case ir::NodeKind::Repeat: repeat(n); break;
      case ir::NodeKind::Instances: instances(n); break;
      case ir::NodeKind::Mesh:
        // The float64 distance is exact; the shader's grid is within its
        // stated error (ir/dump.cpp prints it), a lookup of eight values.
        n.bounds = n.mesh->distance->bounds();
        n.cost += 2;
        break;
      case ir::NodeKind::Elongate: {
        // A bound (issue 49): inside the stretched part the middle section's
        // depth only (0.6 of a stretched box's), and beside it the distance
        // to the middle section, short of the true one where the shape's
        // sections grow away from its centre (0.36).
        n.exact = false;
        const dvec3 h(upper(n.vec.x), upper(n.vec.y), upper(n.vec.z));
        n.bounds = first->bounds.finite() && std::isfinite(h.x + h.y + h.z)
                       ? Aabb{first->bounds.lo - h, first->bounds.hi + h}
                       : Aabb::infinite();
        n.cost += 0.2;
        break;
      }
      case ir::NodeKind::Round:
      case ir::NodeKind::Shell: {
        // An offset of an exact distance is exact: from outside, the nearest
        // point of the grown surface is r further along the same normal;
        // from inside, a ball of depth |d| plus r. It keeps the child's
        // exactness and Lipschitz factor. A shell is exact outside its wall,
        // as a union is outside its shapes (where the march runs); inside
        // the wall, where the shape's inner offset has corners (a box's
        // edges), |d| - r is a bound (0.72 of the depth; docs/language.md).
        const double r = upper(n.amount);
        n.bounds = first->bounds.finite() && std::isfinite(r) ? first->bounds.grow(r) : Aabb::infinite();
        n.cost += 0.1;
        break;
      }
      case ir::NodeKind::Extrude: {
        // Exact for an exact profile (the 2D box corner of profile and slab).
        const double h = upper(n.amount);
        n.bounds = first->bounds.finite() && std::isfinite(h)
                       ? Aabb{dvec3(first->bounds.lo.x, first->bounds.lo.y, -h), dvec3(first->bounds.hi.x, first->bounds.hi.y, h)}
                       : Aabb::infinite();
        n.cost += 0.2;
        break;
      }
      case ir::NodeKind::Revolve: revolve(n); break;
      case ir::NodeKind::Twist:
      case ir::NodeKind::Bend: twist(n); break;
      case ir::NodeKind::Displace: displace(n); break;
      case ir::NodeKind::RepeatPolar: repeatPolar(n); break;
      case ir::NodeKind::Morph: {
        const ir::Interval t = n.amount.range();
        n.exact = false;
        if (t.lo >= 0 && t.hi <= 1) {
          n.bounds = n.children[0]->bounds.unite(n.children[1]->bounds);
        } else {
          // Outside [0, 1] the blend extrapolates and may be negative outside both shapes.
          n.bounds = Aabb::infinite();
          const double l = t.bounded() ? std::max(std::fabs(t.lo) + std::fabs(1 - t.lo),
                                                  std::fabs(t.hi) + std::fabs(1 - t.hi))
                                       : kInf;
          // The checker rejects an unbounded or huge t (checkMorphAmount).
          if (std::isfinite(l)) n.lipschitz = std::max(n.lipschitz, l);
        }
        n.cost += 0.2;
        break;
      }
    }
  }

 private:
  const ir::Scene& scene_;
  Diagnostics& diags_;
  std::unordered_set<ir::Node*> done_;

  void primitive(ir::Node& n) {
    const PrimitiveInfo& info = primitiveInfo(n.primitive);
    if (n.primitive == PrimitiveKind::Polygon) {
      n.bounds = polygonBounds(n.points);
      n.exact = true;
      // Each edge costs about what a box does (its nearest point and its
      // crossing test): 0.67-0.95 boxes a point (bench/primitive_cost.py).
      // At 0.2 a chess piece of two profiles looked worth no box check, and
      // the chess set ran 1.3x slower for it.
      n.cost = 0.8 * static_cast<double>(n.points.size());
      return;
    }
    std::vector<double> hi;
    for (const ir::Scalar& s : n.args) hi.push_back(upper(s));
    bool finite = true;
    for (double v : hi) finite = finite && std::isfinite(v);
    n.bounds = finite ? info.bounds(hi.data()) : Aabb::infinite();
    n.exact = info.exact;
    if (n.primitive == PrimitiveKind::Torus && upper(n.args[1]) > n.args[0].range().lo) n.exact = false;
    n.cost = n.primitive == PrimitiveKind::Menger ? 2 + 2 * n.args[0].value : 1;
  }

  void csg(ir::Node& n) {
    const bool smooth = !n.smooth.isConst() || n.smooth.value > 0;
    if (n.kind == ir::NodeKind::Union) {
      n.bounds = Aabb{};
      for (const ir::NodeRef& c : n.children) n.bounds = n.bounds.unite(c->bounds);
      // The polynomial smooth minimum lowers the field by at most k/4.
      if (smooth) n.bounds = n.bounds.finite() ? n.bounds.grow(upper(n.smooth) / 4) : n.bounds;
    } else if (n.kind == ir::NodeKind::Intersect) {
      n.bounds = Aabb::infinite();
      for (const ir::NodeRef& c : n.children) n.bounds = n.bounds.intersect(c->bounds);
      n.exact = false;
    } else {
      n.bounds = n.children[0]->bounds;
      n.exact = false;
    }
    if (smooth) n.exact = false;
    n.cost += 0.1 * static_cast<double>(n.children.size());
  }

  void buildGrid(ir::Node& n) {
    ir::InstanceSet& set = *n.instances;
    // What is taken off above is beyond any reach: the hierarchy alone, exact.
    if (!std::isfinite(n.lowered)) return;
    if (n.smooth.isConst() && n.smooth.value == 0) {
      buildInstanceGrid(set, n);
    } else if (!scene_.uses_time) {
      // Lists proven per cell from the members' values at its centre (at
      // time 0: a scene that moves keeps the hierarchy alone).
      const Evaluator eval(scene_);
      buildBlendGrid(set, n, upper(n.smooth),
                     [&](size_t i, const glm::dvec3& p) { return eval.instanceDistance(n, i, p); });
    }
  }

  void instances(ir::Node& n) {
    ir::InstanceSet& set = *n.instances;
    const bool smooth = !n.smooth.isConst() || n.smooth.value > 0;
    if (set.nodes.empty() && set.size() > 0) {
      buildInstanceHierarchy(set, n);
      buildGrid(n);
    }
    n.bounds = set.nodes.empty() ? Aabb{} : set.nodes[0].box;
    if (smooth && n.bounds.finite()) n.bounds = n.bounds.grow(upper(n.smooth) / 4);
    n.exact = !smooth;
    n.lipschitz = 0;
    double cost = 0;
    for (const ir::NodeRef& templ : n.children) {
      n.exact = n.exact && templ->exact;
      n.lipschitz = std::max(n.lipschitz, templ->lipschitz);
      cost = std::max(cost, templ->cost);
    }
    // A torus with per-instance parameters may be a spindle somewhere.
    for (size_t i = 0; i < set.size() && n.exact; ++i) {
      const ir::Node& templ = ir::templateOf(n, i);
      if (ir::takesParams(set, templ) && templ.primitive == PrimitiveKind::Torus)
        n.exact = set.paramsOf(i)[1] <= set.paramsOf(i)[0];
    }
    // A visit per hierarchy level and a leaf: what one evaluation costs; a
    // blend grid's lookup and list instead.
    n.cost = (cost * ir::kBvhLeafSize + 1) * (set.depth + 1);
    if (set.grid.blend) {
      const size_t lists = std::count_if(set.grid.count.begin(), set.grid.count.end(), [](std::int32_t c) { return c >= 0; });
      n.cost = cost * double(set.grid.entries.size()) / double(std::max<size_t>(lists, 1)) + 1;
    }
  }

  // twist(rate) about y, k = rate in radians per unit: the child is read at
  // q = R_y(-k y) p. Its Jacobian is R (I + k r t e_y^T), t the unit tangent
  // about the axis at radius r, whose largest singular value is that of
  // [[1, kr], [0, 1]]: (kr + sqrt((kr)^2 + 4)) / 2. Within the radius R that
  // holds the child (a convex cylinder, so the segment to the nearest surface
  // point stays in it) the field is L-Lipschitz with L at r = R; the twist
  // divides by L there, and outside R uses the cylinder's distance (a lower
  // bound: the shape is inside it). tests/twist_test.cpp samples gradients.
  //
  // bend(rate) shares all but the factor: the child is read at q = R_y(k x) p
  // (docs/language.md), which also keeps the distance from the y axis and the
  // height, so the same cylinder holds the bent shape (bendLipschitz).
  void twist(ir::Node& n) {
    const Aabb& b = n.children[0]->bounds;
    const bool bend = n.kind == ir::NodeKind::Bend;
    const char* name = bend ? "bend" : "twist";
    n.exact = false;
    n.cost += 1;
    if (!b.finite()) {
      diags_.error(n.range, std::string("'") + name + "' needs a bounded shape: its stretch grows with the distance "
                            "from the axis, so an unbounded shape has no safe step");
      n.bounds = Aabb::infinite();
      return;
    }
    const double x = std::max(std::fabs(b.lo.x), std::fabs(b.hi.x)), z = std::max(std::fabs(b.lo.z), std::fabs(b.hi.z));
    const double radius = std::sqrt(x * x + z * z);
    const ir::Interval rate = n.amount.range();
    const double k = std::max(std::fabs(rate.lo), std::fabs(rate.hi)) * M_PI / 180;
    // Within reach (1/16 beyond the radius, passes/deform.h) the deformed
    // field over L(reach); beyond, the cylinder's distance, at least radius / 16.
    n.deform_radius = radius;
    const double reach = deformReach(n), kr = k * reach;
    n.deform_radius = radius;
    n.deform_lipschitz = bend ? bendLipschitz(k, reach) : (kr + std::sqrt(kr * kr + 4)) / 2;
    n.bounds = {dvec3(-radius, b.lo.y, -radius), dvec3(radius, b.hi.y, radius)};
    if (bend) {
      // The bent shape lies in the box its child's box bends into. Where the
      // stretch over that box grown by the margin (within the disc: a convex
      // region, as the disc is) is less than over the whole disc, the field
      // is used only there (passes/deform.h).
      const ir::Interval degrees = n.amount.range(), rad{degrees.lo * M_PI / 180, degrees.hi * M_PI / 180};
      n.bounds = n.bounds.intersect(bentBounds(b, rad, radius));
      const double boxed = boxedBendLipschitz(rad, n.bounds.grow(deformMargin(n)), reach);
      if (boxed < n.deform_lipschitz) {
        n.deform_lipschitz = boxed;
        n.deform_boxed = true;
      }
    }
    // At |z| = 1/k the map folds (its Jacobian is singular): points on both
    // sides read the same child point, so the shape shows twice.
    if (bend && k * radius >= 1)
      diags_.warning(n.range, "bend-fold", "'bend' folds space at |z| = " + fmtNumber(1 / k) + " (1 / rate in radians), "
                                           "inside the shape's radius " + fmtNumber(radius) + " about y; the shape "
                                           "is mirrored into itself there (bend less, or keep the shape nearer the "
                                           "y axis)");
  }

  // displace: g = d(p) + a N(s p), N the fractal noise. |grad N(s p)| <= s
  // G_o with G_o = fractalGradientBound(o) for o octaves (eval/noise.h: the
  // most the octaves' bounds add up to along the chain of places they can
  // take together, whatever gradients the hash puts at the corners). So g is
  // (L_child + |a| s G_o)-Lipschitz everywhere; dividing by 1 + |a| s G_o keeps
  // it under L_child (>= 1, which the root's step scale covers). N stays within
  // kNoiseRangeBound, so the surface moves at most |a| times that.
  void displace(ir::Node& n) {
    const ir::Node& c = *n.children[0];
    const ir::Interval a = n.amount.range(), s = n.vec.x.range();
    const double amp = std::max(std::fabs(a.lo), std::fabs(a.hi)), scale = std::max(std::fabs(s.lo), std::fabs(s.hi));
    const int o = n.count.x;
    const double g_octaves = fractalGradientBound(o);
    n.deform_lipschitz = 1 + amp * scale * g_octaves;
    n.exact = false;
    n.bounds = c.bounds.finite() ? c.bounds.grow(amp * kNoiseRangeBound) : c.bounds;
    // An octave of gradient noise hashes and dots 8 lattice gradients and
    // blends them: about as much work as 6 primitives. (At 1.5 the bounds
    // plan saw too little to save: examples/deformations.sdf runs 1.46x with
    // its displaced sphere's box check, bench/results/bounds_plan.md.)
    n.cost += 6 * o;
  }

  // repeat_polar(count): the copies in the sectors polarSectors() names
  // (passes.h: the nearest copy lies among them), each turned back onto
  // sector 0. Exact for an exact child whose copies do not overlap.
  void repeatPolar(ir::Node& n) {
    const Aabb& b = n.children[0]->bounds;
    const int count = n.count.x;
    const PolarSectors s = polarSectors(n);
    n.cost = count == 1 ? n.children[0]->cost : (s.last - s.first + 1) * n.children[0]->cost + 0.5;
    if (count == 1) {
      n.bounds = b;
      return;
    }
    if (!b.finite()) {
      n.bounds = Aabb::infinite();
      n.exact = false;
      diags_.warning(n.range, "repeat-reach", "the shape of 'repeat_polar' is unbounded, so it crosses its "
                                              "sector's edges and its distance may be too large");
      return;
    }
    double r = 0;
    for (int i = 0; i < 4; ++i) {
      const double x = (i & 1) ? b.hi.x : b.lo.x, z = (i & 2) ? b.hi.z : b.lo.z;
      r = std::max(r, std::sqrt(x * x + z * z));
    }
    n.bounds = Aabb{dvec3(-r, b.lo.y, -r), dvec3(r, b.hi.y, r)};
    if (s.half > M_PI / count * (1 + 1e-12)) n.exact = false;  // the copies may overlap
    if (!s.covered) {
      diags_.warning(n.range, "repeat-reach", "the shape of 'repeat_polar' spans more than " +
                                                  std::to_string(kPolarMaxSectors) + " of its " +
                                                  std::to_string(count) + " sectors; copies beyond them are not "
                                                  "checked, so its distance may be too large (keep the shape "
                                                  "off the axis and within a few sectors)");
    } else if (s.last - s.first + 1 > 3) {
      diags_.warning(n.range, "repeat-reach", "the shape of 'repeat_polar' spans several sectors: " +
                                                  std::to_string(s.last - s.first + 1) + " copies are evaluated "
                                                  "at every point (keep it within its sector of " +
                                                  fmtNumber(360.0 / count) + " degrees for 3)");
    }
  }

  // The profile's x is the distance from the axis minus the offset, so only
  // its part at x >= -offset is revolved. A part beyond (x < -offset) is not
  // in the solid but still pulls the distance down: a bound, unless it is the
  // mirror image of the rest (offset 0 and a profile symmetric in x, such as
  // a centred circle: then it is the other half of the same cross-section).
  void revolve(ir::Node& n) {
    const ir::Node& p = *n.children[0];
    const ir::Interval o = n.amount.range();
    n.cost += 0.3;
    if (!p.bounds.finite() || !o.bounded()) {
      n.bounds = Aabb::infinite();
      return;
    }
    const double r = std::max({std::fabs(p.bounds.lo.x + o.lo), std::fabs(p.bounds.hi.x + o.hi),
                               std::fabs(p.bounds.lo.x + o.hi), std::fabs(p.bounds.hi.x + o.lo)});
    n.bounds = {dvec3(-r, p.bounds.lo.y, -r), dvec3(r, p.bounds.hi.y, r)};
    // A polygon's edges on the axis sweep no surface: inside, the distance
    // to them (the distance to the axis) is less than the depth, so they are
    // left out (shapes/primitives.h). A shell of the solid had a wall along
    // its axis.
    if (p.kind == ir::NodeKind::Primitive && p.primitive == PrimitiveKind::Polygon && n.amount.isConst())
      for (size_t i = 0; i < p.points.size(); ++i)
        n.lathe = n.lathe || (p.points[i].x == -n.amount.value && p.points[(i + 1) % p.points.size()].x == -n.amount.value);
    if (p.bounds.lo.x + o.lo >= 0) return;
    if (n.amount.isConst() && n.amount.value == 0 && mirrorSymmetricX(p)) return;
    n.exact = false;
    diags_.warning(n.range, "bound", "the profile of 'revolve' reaches across the axis (x < -offset = " +
                                         fmtNumber(-o.lo) + "); that part is not revolved, and the distance "
                                         "is only a bound (move the profile to x >= -offset)");
  }

  // Whether a profile is its own mirror image in x = 0 (centred primitives,
  // and CSG, offsets and y-moves of such).
  static bool mirrorSymmetricX(const ir::Node& n) {
    switch (n.kind) {
      case ir::NodeKind::Primitive:
        if (n.primitive != PrimitiveKind::Polygon) return true;
        for (const glm::dvec2& a : n.points) {
          bool mirrored = false;
          for (const glm::dvec2& b : n.points) mirrored = mirrored || (b.x == -a.x && b.y == a.y);
          if (!mirrored) return false;
        }
        return true;
      case ir::NodeKind::Union:
      case ir::NodeKind::Intersect:
      case ir::NodeKind::Subtract:
      case ir::NodeKind::Round:
      case ir::NodeKind::Shell:
      case ir::NodeKind::Scale:
        for (const ir::NodeRef& c : n.children)
          if (!mirrorSymmetricX(*c)) return false;
        return true;
      case ir::NodeKind::Translate:
        return n.vec.x.isConst() && n.vec.x.value == 0 && mirrorSymmetricX(*n.children[0]);
      case ir::NodeKind::Affine:
        // A map that commutes with x -> -x: no mixing of x with y, z, no x move.
        return n.offset.x == 0 && n.linear[0][1] == 0 && n.linear[0][2] == 0 && n.linear[1][0] == 0 &&
               n.linear[2][0] == 0 && mirrorSymmetricX(*n.children[0]);
      default: return false;
    }
  }

  static std::string fmtNumber(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
  }

  void repeat(ir::Node& n) {
    const ir::Node& child = *n.children[0];
    const dvec3 cell = n.vec.value();
    n.bounds = child.bounds;
    double cells_evaluated = 1;
    for (int a = 0; a < 3; ++a) {
      if (cell[a] == 0) continue;
      if (n.count[a] == 0) {
        n.bounds.lo[a] = -1e300;
        n.bounds.hi[a] = 1e300;
      } else if (child.bounds.finite()) {
        const double spread = (n.count[a] - 1) * 0.5 * cell[a];
        n.bounds.lo[a] -= spread;
        n.bounds.hi[a] += spread;
      }
      const RepeatCells r = repeatCells(n, a);
      cells_evaluated *= 2 * r.side + 1;
      // Overlapping copies: their min is a bound inside (passes.h).
      if (r.side > 0 && (!r.covered || r.half > cell[a] / 2)) n.exact = false;
      const std::string axis(1, "xyz"[a]);
      if (!r.covered && !child.bounds.finite())
        diags_.warning(n.range, "repeat-reach", "the repeated shape is unbounded; only the neighbouring cells "
                                                "along axis " + axis + " are checked, so its distance may be "
                                                "too large");
      else if (!r.covered)
        diags_.warning(n.range, "repeat-reach", "the repeated shape spans more than " +
                                                    std::to_string(2 * kRepeatMaxSide + 1) + " cells along axis " +
                                                    axis + "; copies beyond them are not checked, so its "
                                                    "distance may be too large (use a larger cell)");
      else if (r.side > 1)
        diags_.warning(n.range, "repeat-reach", "the repeated shape is wider than its cell along axis " + axis +
                                                    ": " + std::to_string(2 * r.side + 1) + " copies are "
                                                    "evaluated along it at every point (use a larger cell for 3)");
    }
    n.cost = child.cost * cells_evaluated + 0.5;
  }
};

}  // namespace

Aabb transformBox(const Aabb& b, const glm::dmat3& m, const dvec3& t) {
  if (!b.finite()) return b.empty() ? b : Aabb::infinite();
  Aabb out;
  for (int i = 0; i < 8; ++i) {
    const dvec3 corner((i & 1) ? b.hi.x : b.lo.x, (i & 2) ? b.hi.y : b.lo.y, (i & 4) ? b.hi.z : b.lo.z);
    const dvec3 q = m * corner + t;
    out.lo = glm::min(out.lo, q);
    out.hi = glm::max(out.hi, q);
  }
  return out;
}

double repeatReach(const ir::Node& repeat, int axis) {
  const Aabb& b = repeat.children[0]->bounds;
  return b.finite() ? std::max(std::fabs(b.lo[axis]), std::fabs(b.hi[axis])) : kInf;
}

bool repeatOffCentre(const ir::Node& repeat, int axis) {
  const Aabb& b = repeat.children[0]->bounds;
  // A few ulps of the reach: a centred child's bounds cancel to rounding.
  return b.finite() && std::fabs(b.lo[axis] + b.hi[axis]) > 1e-9 * repeatReach(repeat, axis);
}

bool mirrorSymmetric(const ir::Node& n, int axis) {
  switch (n.kind) {
    case ir::NodeKind::Primitive:
      switch (n.primitive) {
        case PrimitiveKind::Sphere:
        case PrimitiveKind::Box:
        case PrimitiveKind::Torus:
        case PrimitiveKind::Cylinder:
        case PrimitiveKind::Capsule:
        case PrimitiveKind::HexPrism:
        case PrimitiveKind::Menger:
        case PrimitiveKind::Octahedron:
        case PrimitiveKind::Ellipsoid:
        case PrimitiveKind::Circle:
        case PrimitiveKind::Rect:
        case PrimitiveKind::Hexagon: return true;
        // Apex or base on y = 0: symmetric across x = 0 and z = 0 only.
        case PrimitiveKind::Cone:
        case PrimitiveKind::Pyramid:
        case PrimitiveKind::RoundCone:
        case PrimitiveKind::TriPrism: return axis != 1;
        case PrimitiveKind::Polygon:
          if (axis == 2) return true;
          for (const glm::dvec2& a : n.points) {
            bool mirrored = false;
            for (const glm::dvec2& b : n.points)
              mirrored = mirrored || (axis == 0 ? (b.x == -a.x && b.y == a.y) : (b.x == a.x && b.y == -a.y));
            if (!mirrored) return false;
          }
          return true;
        default: return false;
      }
    case ir::NodeKind::Union:
    case ir::NodeKind::Intersect:
    case ir::NodeKind::Subtract:
    case ir::NodeKind::Round:
    case ir::NodeKind::Shell:
    case ir::NodeKind::Scale:
    case ir::NodeKind::Elongate:
      for (const ir::NodeRef& c : n.children)
        if (!mirrorSymmetric(*c, axis)) return false;
      return true;
    case ir::NodeKind::Translate:
    {
      const ir::Scalar& o = axis == 0 ? n.vec.x : axis == 1 ? n.vec.y : n.vec.z;
      return o.isConst() && o.value == 0 && mirrorSymmetric(*n.children[0], axis);
    }
    case ir::NodeKind::Affine: {
      // local = L p + o. When p's `axis` feeds local's axis b alone and
      // nothing else feeds b (an axis-aligned turn, up to rounding: cos 90
      // degrees is 6e-17), and o moves nothing along b, flipping p's axis
      // flips local's b: symmetric when the child is across b.
      const glm::dmat3& l = n.linear;  // column-major: l[column][row]
      double big = 0;
      for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) big = std::max(big, std::fabs(l[c][r]));
      const double tiny = 1e-12 * big;
      int b = 0;
      for (int r = 1; r < 3; ++r)
        if (std::fabs(l[axis][r]) > std::fabs(l[axis][b])) b = r;
      for (int r = 0; r < 3; ++r)
        if (r != b && std::fabs(l[axis][r]) > tiny) return false;
      for (int c = 0; c < 3; ++c)
        if (c != axis && std::fabs(l[c][b]) > tiny) return false;
      return std::fabs(n.offset[b]) <= 1e-12 * (1 + glm::length(n.offset)) && mirrorSymmetric(*n.children[0], b);
    }
    default: return false;
  }
}

RepeatCells repeatCells(const ir::Node& repeat, int axis) {
  RepeatCells r;
  const double cell = repeat.vec.value()[axis];
  if (cell == 0) return r;
  const Aabb& b = repeat.children[0]->bounds;
  if (!b.finite()) {
    r.side = 1;
    r.covered = false;
    return r;
  }
  if (!repeatOffCentre(repeat, axis) && repeatReach(repeat, axis) <= cell / 2 &&
      mirrorSymmetric(*repeat.children[0], axis))
    return r;
  r.centre = (b.lo[axis] + b.hi[axis]) / 2;
  const double h = (b.hi[axis] - b.lo[axis]) / 2;
  r.half = h;
  // ceil(h / c), a few ulps under a whole number taken as that number.
  const double need = std::max(1.0, std::ceil(h / cell - 1e-9));
  r.side = int(std::min<double>(need, kRepeatMaxSide));
  r.covered = need <= kRepeatMaxSide;
  return r;
}

PolarSectors polarSectors(const ir::Node& n) {
  PolarSectors s;
  const int count = n.count.x;
  if (count <= 1) {
    s.first = s.last = 0;
    return s;
  }
  const double w = 2 * M_PI / count;
  const Aabb& b = n.children[0]->bounds;
  double half = M_PI;  // the half angle the child's box spans about `centre`
  if (b.finite() && !(b.lo.x <= 0 && b.hi.x >= 0 && b.lo.z <= 0 && b.hi.z >= 0)) {
    // The box's xz rectangle leaves out the axis, so it spans under pi:
    // its corners' angles about the direction of its centre.
    s.centre = std::atan2((b.lo.z + b.hi.z) / 2, (b.lo.x + b.hi.x) / 2);
    double lo = 0, hi = 0;
    for (int i = 0; i < 4; ++i) {
      const double x = (i & 1) ? b.hi.x : b.lo.x, z = (i & 2) ? b.hi.z : b.lo.z;
      const double a = std::remainder(std::atan2(z, x) - s.centre, 2 * M_PI);
      lo = std::min(lo, a);
      hi = std::max(hi, a);
    }
    s.centre += (lo + hi) / 2;
    half = (hi - lo) / 2;
  }
  s.half = half;
  // Sectors within ceil(half / w) of the nearest, or every copy.
  const int need = int(std::max(1.0, std::ceil(half / w - 1e-9)));
  if (2 * need + 1 < count && 2 * need + 1 <= kPolarMaxSectors) {
    s.first = -need;
    s.last = need;
    return s;
  }
  const int all = std::min(count, kPolarMaxSectors);
  s.first = -(all - 1) / 2;
  s.last = all / 2;
  s.covered = all == count;
  return s;
}

namespace {

void clearLowered(ir::Node& n, std::unordered_set<const ir::Node*>& seen) {
  if (!seen.insert(&n).second) return;
  n.lowered = 0;
  for (const ir::NodeRef& c : n.children) clearLowered(*c, seen);
}

// The deepest a field can be inside a shape within `b`: half its thinnest
// side (an exact field or a bound, either no deeper than the true depth).
double deepestInside(const Aabb& b) {
  if (!b.finite()) return std::numeric_limits<double>::infinity();
  if (b.empty()) return 0;
  return 0.5 * std::min({b.hi.x - b.lo.x, b.hi.y - b.lo.y, b.hi.z - b.lo.z});
}

// The largest |x| of a scalar over time.
double magnitude(const ir::Scalar& x) { return std::max(std::fabs(x.range().lo), std::fabs(x.range().hi)); }

// ir::Node::lowered, top down: what each node above may take off its value.
// A shared node (a `let` shape used twice) keeps the most of its uses. Run
// before analyze's bottom-up pass (which builds the sets' grids) and again
// after it, when the bounds and the deformations' stretches below are known.
void markLowered(ir::Node& n, double by, std::unordered_set<const ir::Node*>& seen) {
  if (!seen.insert(&n).second && by <= n.lowered) return;
  n.lowered = std::max(n.lowered, by);
  double below = by;
  switch (n.kind) {
    case ir::NodeKind::Round:
    case ir::NodeKind::Shell:
      // child - r, |child| - r.
      below += magnitude(n.amount);
      break;
    case ir::NodeKind::Displace:
      // (child + a noise) / stretch, |noise| <= 1.
      below = below * n.deform_lipschitz + magnitude(n.amount);
      break;
    case ir::NodeKind::Twist:
    case ir::NodeKind::Bend:
      // child / stretch.
      below *= n.deform_lipschitz;
      break;
    case ir::NodeKind::Morph: {
      // t a + (1 - t) b: a bound in a is brought down by the other's weight
      // times how deep inside b can be, and divided by a's weight. Outside
      // t in [0, 1], or with a weight near 0, nothing can be taken off.
      const ir::Interval t = n.amount.range();
      const double inf = std::numeric_limits<double>::infinity();
      for (int i = 0; i < 2 && n.children.size() == 2; ++i) {
        const double w_lo = i == 0 ? t.lo : 1 - t.hi, w_hi = i == 0 ? t.hi : 1 - t.lo;
        const double other = w_lo >= 0 && w_hi <= 1 && w_lo > 0.01
                                 ? (below + (1 - w_lo) * deepestInside(n.children[1 - i]->bounds)) / w_lo
                                 : inf;
        markLowered(*n.children[i], std::isfinite(other) ? other : inf, seen);
      }
      return;
    }
    case ir::NodeKind::Union:
    case ir::NodeKind::Intersect:
    case ir::NodeKind::Subtract:
    case ir::NodeKind::Instances:
      // A smooth blend lowers (raises) the nearest value by at most 1.25 k
      // (docs/language.md); one child has nothing to blend with (a set's
      // copies do).
      if ((!n.smooth.isConst() || n.smooth.value > 0) &&
          (n.children.size() > 1 || n.kind == ir::NodeKind::Instances))
        below += 1.25 * magnitude(n.smooth);
      break;
    case ir::NodeKind::Scale: {
      // s child(p / s): the child's units are 1 / s of these.
      const double s = n.amount.range().lo;
      below = s > 0 ? below / s : below;
      break;
    }
    case ir::NodeKind::ScaleNonUniform: {
      const double s = std::min({n.vec.x.range().lo, n.vec.y.range().lo, n.vec.z.range().lo});
      below = s > 0 ? below / s : below;
      break;
    }
    case ir::NodeKind::Affine:
      below = n.scale > 0 ? below / n.scale : below;
      break;
    default:
      break;
  }
  if (std::isnan(below)) below = std::numeric_limits<double>::infinity();
  for (const ir::NodeRef& c : n.children) markLowered(*c, below, seen);
}

void collectSets(ir::Node& n, std::unordered_set<const ir::Node*>& seen, std::vector<ir::Node*>& out) {
  if (!seen.insert(&n).second) return;
  if (n.kind == ir::NodeKind::Instances) out.push_back(&n);
  for (const ir::NodeRef& c : n.children) collectSets(*c, seen, out);
}

}  // namespace

void analyze(ir::Scene& scene, Diagnostics& diags) {
  if (!scene.root) return;
  std::unordered_set<const ir::Node*> seen;
  clearLowered(*scene.root, seen);
  seen.clear();
  markLowered(*scene.root, 0, seen);
  Analyzer analyzer(scene, diags);
  analyzer.visit(*scene.root);
  // Again with the bounds and stretches the pass found: a set below a
  // deformation or a morph may need more than its grid was built for.
  std::vector<ir::Node*> sets;
  seen.clear();
  collectSets(*scene.root, seen, sets);
  if (sets.empty()) return;
  std::vector<double> built;
  for (const ir::Node* n : sets) built.push_back(n->lowered);
  seen.clear();
  clearLowered(*scene.root, seen);
  seen.clear();
  markLowered(*scene.root, 0, seen);
  // (A grid not built for want of a finite value, bounds unknown then, is built now.)
  for (size_t i = 0; i < sets.size(); ++i)
    if (sets[i]->lowered > built[i] || (!std::isfinite(built[i]) && std::isfinite(sets[i]->lowered)))
      analyzer.rebuildGrid(*sets[i]);
}

namespace {

// The thinnest side of a box: float32 resolves the faces across it to ulps
// of that, however long the box is.
double thinnestSide(const Aabb& b) { return std::min({b.hi.x - b.lo.x, b.hi.y - b.lo.y, b.hi.z - b.lo.z}); }

// The thinnest side of the finite parts of n (at most `size`), looking
// through unions (their children are parts) and instance sets (each copy is).
double thinnestPart(const ir::Node& n, double size) {
  if (n.kind == ir::NodeKind::Union) {
    for (const ir::NodeRef& c : n.children) size = thinnestPart(*c, size);
    return size;
  }
  if (n.kind == ir::NodeKind::Instances && !n.children.empty()) {
    const ir::InstanceSet& set = *n.instances;
    for (size_t i = 0; i < set.size(); ++i) {
      const Aabb b = instanceBounds(set, i, n);
      if (b.finite() && !b.empty()) size = std::min(size, std::max(thinnestSide(b), 1e-12));
    }
    return size;
  }
  if (n.bounds.finite() && !n.bounds.empty()) size = std::min(size, std::max(thinnestSide(n.bounds), 1e-12));
  return size;
}

}  // namespace

MarchLimits deriveMarchLimits(const ir::Scene& scene, const MarchPolicy& policy) {
  MarchLimits m;
  if (policy.paper_baseline || !scene.root) {
    m.max_distance = 100;
    m.max_steps = 256;
    m.hit_epsilon = 1e-3;
    m.pixel_cone = 0;
    m.step_scale = 1;
    return m;
  }
  const ir::Node& root = *scene.root;
  // The finite part of the scene sets its scale; infinite children (planes,
  // repetitions) are seen out to many times that.
  Aabb finite_part;
  bool has_infinite = false;
  for (const ir::NodeRef& c : root.children) {
    if (c->bounds.finite()) finite_part = finite_part.unite(c->bounds);
    else has_infinite = true;
  }
  const dvec3 eye = scene.camera.position;
  double size = 1, reach = 10;
  if (finite_part.finite()) {
    size = std::max(glm::length(finite_part.hi - finite_part.lo), 1e-6);
    reach = glm::length(glm::max(glm::abs(finite_part.lo - eye), glm::abs(finite_part.hi - eye)));
  }
  m.max_distance = has_infinite ? std::max(reach * 8, size * 20) : reach * 1.05;
  // The hit tolerance is local (pathtrace.glsl fpEps/hitEps): float32's
  // resolution at the point and a pixel's footprint at its distance. This is
  // only a floor for points near the origin, where float32 resolves ~0: a
  // millionth of the smallest finite top-level part, so a 2000-wide ground
  // does not coarsen a 0.1 sphere on it (issue 17: 22% of its pixels were off).
  // Parts are looked for inside unions and instance sets: a set's or a
  // union's box spans its spread, and one copy 1e6 away made 45 spheres of
  // radius 0.5 a slab (a floor of 1.0).
  m.hit_epsilon = thinnestPart(root, size) * 1e-6;
  m.pixel_cone = 0.25 * 2 * std::tan(glm::radians(scene.camera.fov_degrees) / 2) /
                 std::max(policy.image_height > 0 ? policy.image_height : scene.render.height, 1);
  m.step_scale = 1 / std::max(root.lipschitz, 1.0);
  // Bounds and blends shorten steps; infinite parts lengthen rays.
  int steps = 160;
  if (!root.exact) steps += 64;
  if (has_infinite) steps += 64;
  // A ray meeting a flat face at angle a shrinks its distance by (1 - sin a)
  // per step and stops in the quarter-pixel band t * cone: ln(sin a / cone) /
  // sin a steps, at most 1 / (e * cone) (at sin a = e * cone). Grazing rows
  // below a marched horizon need that many, not a fixed 160 (issue 17).
  const int grazing = static_cast<int>(std::ceil(1.0 / (std::exp(1.0) * std::max(m.pixel_cone, 1e-9))));
  steps = std::max(steps, std::min(grazing + 32, 1024));
  m.max_steps = std::min(static_cast<int>(steps / m.step_scale), std::max(512, steps));
  return m;
}

double stretchBelow(const ir::Node& n) {
  double below = 1;
  for (const ir::NodeRef& c : n.children) below = std::max(below, stretchBelow(*c));
  // A bounded displace is no less than the distance to its own box outside
  // it, whatever is below it: a box holding it needs no division.
  if (n.kind == ir::NodeKind::Displace && n.bounds.finite()) return 1;
  const bool divides = n.kind == ir::NodeKind::Twist || n.kind == ir::NodeKind::Bend || n.kind == ir::NodeKind::Displace;
  return divides ? below * n.deform_lipschitz : below;
}

}  // namespace sdfc
