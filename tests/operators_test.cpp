// CSG and domain operators of the float64 evaluator against computations
// written here independently: exact where the operator is exact (union of
// disjoint shapes, rigid motions, uniform scale, reflect, repetition against
// brute force over many copies, elongation), the documented bounds where it is
// not (smooth blends, non-uniform scale), and transform fusion as a no-op on
// distances.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "driver/compile.h"
#include "eval/evaluator.h"

namespace sdfc {
namespace {

using glm::dmat3;
using glm::dvec3;

constexpr double kPi = 3.14159265358979323846;

// A checked scene kept alive with its evaluator.
struct Compiled {
  CompiledScene scene;
  double distance(dvec3 p, double time = 0) const { return Evaluator(scene.scene, time).distance(p); }
};

Compiled compile(const std::string& body, bool fuse = true) {
  CompileOptions options;
  options.fuse_transforms = fuse;
  Diagnostics diags;
  Compiled c{checkSource("t.sdf", "scene { " + body + " }\n", options, diags)};
  EXPECT_TRUE(c.scene.ok) << body << "\n" << diags.format();
  return c;
}

// Independent reference shapes.
double sphere(dvec3 p, double r) { return std::sqrt(glm::dot(p, p)) - r; }
double box(dvec3 p, dvec3 size) {
  const dvec3 h = size / 2.0;
  const dvec3 outside = glm::max(glm::abs(p) - h, dvec3(0));
  if (outside != dvec3(0)) return glm::length(outside);
  const dvec3 gap = h - glm::abs(p);
  return -std::min({gap.x, gap.y, gap.z});
}

// Rotation matrices from a unit quaternion (not Rodrigues, unlike the
// compiler) and from elementary axis rotations.
dmat3 quaternionRotation(dvec3 axis, double degrees) {
  axis = glm::normalize(axis);
  const double half = degrees * kPi / 360;
  const double w = std::cos(half), x = axis.x * std::sin(half), y = axis.y * std::sin(half),
               z = axis.z * std::sin(half);
  dmat3 m;  // m[col][row]
  m[0] = {1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y)};
  m[1] = {2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x)};
  m[2] = {2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)};
  return m;
}
dmat3 eulerRotation(dvec3 degrees) {
  const dvec3 a = degrees * (kPi / 180);
  const dmat3 rx(1, 0, 0, 0, std::cos(a.x), std::sin(a.x), 0, -std::sin(a.x), std::cos(a.x));
  const dmat3 ry(std::cos(a.y), 0, -std::sin(a.y), 0, 1, 0, std::sin(a.y), 0, std::cos(a.y));
  const dmat3 rz(std::cos(a.z), std::sin(a.z), 0, -std::sin(a.z), std::cos(a.z), 0, 0, 0, 1);
  return rz * ry * rx;  // x applied first
}

std::vector<dvec3> randomPoints(int n, double extent, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-extent, extent);
  std::vector<dvec3> pts;
  for (int i = 0; i < n; ++i) pts.push_back({u(rng), u(rng), u(rng)});
  return pts;
}

constexpr double kExact = 1e-12;

TEST(Operators, RotationMatricesAgreeWithEachOther) {
  // Sanity of the test's own references: a quarter turn about z maps x to y.
  const dvec3 y = quaternionRotation({0, 0, 1}, 90) * dvec3(1, 0, 0);
  EXPECT_NEAR(glm::length(y - dvec3(0, 1, 0)), 0, 1e-15);
  const dmat3 a = eulerRotation({0, 0, 37}), b = quaternionRotation({0, 0, 1}, 37);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(glm::length(a[c] - b[c]), 0, 1e-15);
}

TEST(Operators, UnionOfDisjointSpheresIsExact) {
  const Compiled c = compile("sphere(radius: 0.5) translate([2, 0.5, 0]) { sphere(radius: 0.7) }");
  for (dvec3 p : randomPoints(3000, 3, 1))
    ASSERT_NEAR(c.distance(p), std::min(sphere(p, 0.5), sphere(p - dvec3(2, 0.5, 0), 0.7)), kExact);
}

TEST(Operators, SharpIntersectAndSubtract) {
  const Compiled i = compile("intersect { box(size: [1, 1, 1]) sphere(radius: 0.65) }");
  const Compiled s = compile("subtract { box(size: [1, 1, 1]) sphere(radius: 0.65) }");
  for (dvec3 p : randomPoints(3000, 1.5, 2)) {
    ASSERT_NEAR(i.distance(p), std::max(box(p, dvec3(1)), sphere(p, 0.65)), kExact);
    ASSERT_NEAR(s.distance(p), std::max(box(p, dvec3(1)), -sphere(p, 0.65)), kExact);
  }
}

TEST(Operators, RotateAxisAngleIsBoxAtInverseRotatedPoint) {
  const dvec3 axis(1, 2, 0.5), size(1.4, 0.4, 0.8);
  for (bool fuse : {false, true}) {
    const Compiled c = compile("rotate(axis: [1, 2, 0.5], degrees: 37) { box(size: [1.4, 0.4, 0.8]) }", fuse);
    const dmat3 r = quaternionRotation(axis, 37);
    for (dvec3 p : randomPoints(3000, 1.5, 3))
      ASSERT_NEAR(c.distance(p), box(glm::transpose(r) * p, size), kExact);
  }
}

TEST(Operators, RotateEulerAppliesXThenYThenZ) {
  const dvec3 size(1.4, 0.4, 0.8);
  for (bool fuse : {false, true}) {
    const Compiled c = compile("rotate(euler: [20, -35, 70]) { box(size: [1.4, 0.4, 0.8]) }", fuse);
    const dmat3 r = eulerRotation({20, -35, 70});
    for (dvec3 p : randomPoints(3000, 1.5, 4))
      ASSERT_NEAR(c.distance(p), box(glm::transpose(r) * p, size), kExact);
  }
}

TEST(Operators, TranslateRotateScaleCompose) {
  // World from local: p = t + R * (s * local).
  const dvec3 t(0.3, -0.2, 0.5), size(0.6, 0.3, 0.5);
  const dmat3 r = quaternionRotation({0, 1, 1}, -50);
  for (bool fuse : {false, true}) {
    const Compiled c = compile(
        "translate([0.3, -0.2, 0.5]) { rotate(axis: [0, 1, 1], degrees: -50) { scale(1.7) {"
        " box(size: [0.6, 0.3, 0.5]) } } }",
        fuse);
    for (dvec3 p : randomPoints(3000, 2, 5)) {
      const dvec3 local = glm::transpose(r) * (p - t) / 1.7;
      ASSERT_NEAR(c.distance(p), 1.7 * box(local, size), kExact);
    }
  }
}

TEST(Operators, UniformScaleIsExact) {
  const Compiled c = compile("scale(2.5) { box(size: [0.4, 0.2, 0.6]) }");
  for (dvec3 p : randomPoints(3000, 2, 6))
    ASSERT_NEAR(c.distance(p), box(p, dvec3(1.0, 0.5, 1.5)), kExact);
}

// Non-uniform scale is a bound: right sign, never above the true distance
// (here: of an ellipsoid, measured against a dense surface sampling), and
// 1-Lipschitz.
TEST(Operators, NonUniformScaleIsABound) {
  const Compiled c = compile("scale([1, 2, 0.5]) { sphere(radius: 0.5) }");
  const dvec3 s(1, 2, 0.5);
  std::vector<dvec3> surface;
  for (int i = 0; i <= 200; ++i)
    for (int j = 0; j <= 400; ++j) {
      const double t = kPi * i / 200, f = 2 * kPi * j / 400;
      surface.push_back(0.5 * s * dvec3(std::sin(t) * std::cos(f), std::cos(t), std::sin(t) * std::sin(f)));
    }
  for (dvec3 p : randomPoints(300, 1.5, 7)) {
    const double d = c.distance(p);
    EXPECT_EQ(d < 0, glm::length(p / s) < 0.5);
    double nearest = 1e300;
    for (const dvec3& q : surface) nearest = std::min(nearest, glm::length(p - q));
    ASSERT_LE(std::fabs(d), nearest + 1e-12);
  }
  for (dvec3 p : randomPoints(2000, 1.5, 8)) {
    const dvec3 e = glm::normalize(dvec3(0.3, -0.7, 0.2)) * 1e-3;
    ASSERT_LE(std::fabs(c.distance(p + e) - c.distance(p)), 1e-3 + 1e-12);
  }
}

TEST(Operators, ReflectMirrorsTheFrontHalf) {
  // A sphere in front of the plane x + y = 0.1 (normalised): the union of it
  // and its mirror image, exactly.
  const Compiled c =
      compile("reflect(normal: [1, 1, 0], offset: 0.1) { translate([0.6, 0, 0.2]) { sphere(radius: 0.3) } }");
  const dvec3 n = glm::normalize(dvec3(1, 1, 0));
  const dvec3 centre(0.6, 0, 0.2);
  const dvec3 mirrored = centre - 2 * (glm::dot(centre, n) - 0.1) * n;
  for (dvec3 p : randomPoints(3000, 1.5, 9))
    ASSERT_NEAR(c.distance(p), std::min(sphere(p - centre, 0.3), sphere(p - mirrored, 0.3)), kExact);
}

// Repetition against the minimum over many explicit copies.
double bruteRepeat(dvec3 p, dvec3 cell, glm::ivec3 count, const std::function<double(dvec3)>& child) {
  double best = 1e300;
  glm::ivec3 lo, hi;
  for (int a = 0; a < 3; ++a) {
    if (cell[a] == 0) lo[a] = hi[a] = 0;
    else if (count[a] == 0) lo[a] = -12, hi[a] = 12;  // wide enough for |p| <= 3
    else lo[a] = 0, hi[a] = count[a] - 1;
  }
  for (int i = lo.x; i <= hi.x; ++i)
    for (int j = lo.y; j <= hi.y; ++j)
      for (int k = lo.z; k <= hi.z; ++k) {
        dvec3 offset(i, j, k);
        for (int a = 0; a < 3; ++a)
          if (count[a] > 0) offset[a] -= (count[a] - 1) / 2.0;
        best = std::min(best, child(p - offset * cell));
      }
  return best;
}

TEST(Operators, InfiniteRepeatWithChildOverlappingTheCellBorder) {
  // The box spans x in [-0.15, 0.75] of a 1-wide cell: it reaches into the
  // neighbour cell, so the evaluator must look there too.
  const Compiled c = compile("repeat(cell: [1, 0, 1]) { translate([0.3, 0, 0]) { box(size: [0.9, 0.5, 0.4]) } }");
  auto child = [](dvec3 q) { return box(q - dvec3(0.3, 0, 0), dvec3(0.9, 0.5, 0.4)); };
  for (dvec3 p : randomPoints(3000, 3, 10))
    ASSERT_NEAR(c.distance(p), bruteRepeat(p, {1, 0, 1}, {0, 0, 0}, child), kExact)
        << p.x << " " << p.y << " " << p.z;
}

TEST(Operators, LimitedRepeatWithCount) {
  const Compiled c = compile("repeat(cell: [0.8, 0.8, 0], count: [3, 2, 0]) { sphere(radius: 0.5) }");
  auto child = [](dvec3 q) { return sphere(q, 0.5); };
  for (dvec3 p : randomPoints(3000, 3, 11))
    ASSERT_NEAR(c.distance(p), bruteRepeat(p, {0.8, 0.8, 0}, {3, 2, 0}, child), kExact)
        << p.x << " " << p.y << " " << p.z;
}

// A child that sits off-centre in its cell (here, mostly in the next cell
// over) is reached only from the far side; the evaluator must consider the
// neighbour on either side, not only the one toward the point.
// (Both once took only the neighbour on the point's side: ~40% of these
// points got the wrong distance.)
TEST(Operators, RepeatWithOffCentreChild) {
  const Compiled c = compile("repeat(cell: [1, 0, 0]) { translate([0.9, 0, 0]) { sphere(radius: 0.3) } }");
  auto child = [](dvec3 q) { return sphere(q - dvec3(0.9, 0, 0), 0.3); };
  int wrong = 0;
  for (dvec3 p : randomPoints(3000, 3, 12))
    wrong += std::fabs(c.distance(p) - bruteRepeat(p, {1, 0, 0}, {0, 0, 0}, child)) > kExact;
  EXPECT_EQ(wrong, 0) << "points where repeat misses the nearest copy";
}

// A child inside its cell but off its centre: a copy in the next cell can be
// nearer than the cell's own (cell 2, the copy in [0.5, 1] along x: at x = -0.9
// the own copy is 1.4 away, the next cell's 0.1). Only the own cell was once
// evaluated, so the distance was 14x too large there and a march along x
// stepped through the nearer copy. The three cells give the exact distance.
TEST(Operators, RepeatWithOffCentreChildInsideItsCell) {
  const Compiled c = compile("repeat(cell: [2, 0, 1.5]) { translate([0.75, 0.3, -0.4]) { box(size: [0.5, 0.5, 0.5]) } }");
  auto child = [](dvec3 q) { return box(q - dvec3(0.75, 0.3, -0.4), dvec3(0.5, 0.5, 0.5)); };
  EXPECT_NEAR(c.distance({-0.9, 0.3, -0.4}), 0.1, kExact);
  for (dvec3 p : randomPoints(3000, 4, 13))
    ASSERT_NEAR(c.distance(p), bruteRepeat(p, {2, 0, 1.5}, {0, 0, 0}, child), kExact)
        << p.x << " " << p.y << " " << p.z;
  EXPECT_TRUE(c.scene.scene.root->exact);
}

// Offsets: a rounded box is a box grown by the radius (the rounded box of
// the larger size), a shell of a sphere is | |p| - r | - t / 2, and both keep
// the child's material and exactness.
TEST(Operators, RoundAndShellAreExactOffsets) {
  const Compiled rounded = compile("round(radius: 0.2) { box(size: [1, 1, 1]) }");
  const Compiled grown = compile("box(size: [1.4, 1.4, 1.4], rounding: 0.2)");
  const Compiled shelled = compile("shell(thickness: 0.2) { sphere(radius: 1) }");
  const Compiled zero = compile("round(radius: 0) { torus(major: 0.6, minor: 0.2) }");
  const Compiled torus = compile("torus(major: 0.6, minor: 0.2)");
  for (dvec3 p : randomPoints(3000, 2, 29)) {
    ASSERT_NEAR(rounded.distance(p), grown.distance(p), kExact);
    ASSERT_NEAR(shelled.distance(p), std::fabs(glm::length(p) - 1) - 0.1, kExact);
    ASSERT_EQ(zero.distance(p), torus.distance(p));
  }
  EXPECT_TRUE(rounded.scene.scene.root->exact);
  EXPECT_TRUE(shelled.scene.scene.root->exact);
  // A bound stays a bound.
  EXPECT_FALSE(compile("round(radius: 0.1) { ellipsoid(radii: [1, 0.5, 0.5]) }").scene.scene.root->exact);
}

TEST(Operators, ElongatedSphereIsACapsuleAndElongatedBoxABiggerBox) {
  const Compiled e = compile("elongate([0, 1.2, 0]) { sphere(radius: 0.4) }");
  const Compiled cap = compile("capsule(radius: 0.4, height: 1.2)");
  const Compiled b = compile("elongate([0.6, 0, 0.2]) { box(size: [0.5, 0.5, 0.5]) }");
  for (dvec3 p : randomPoints(3000, 1.5, 13)) {
    const dvec3 seg(0, std::clamp(p.y, -0.6, 0.6), 0);
    ASSERT_NEAR(e.distance(p), glm::length(p - seg) - 0.4, kExact);
    ASSERT_NEAR(e.distance(p), cap.distance(p), kExact);
    // Outside, elongation is the Minkowski sum with a segment/rectangle: exact.
    const double bigger = box(p, dvec3(1.1, 0.5, 0.7));
    if (bigger > 0) {
      ASSERT_NEAR(b.distance(p), bigger, kExact);
    } else {
      ASSERT_LT(b.distance(p), 0);
    }
  }
}

TEST(Operators, SmoothUnionLiesWithinAQuarterOfTheRadiusBelowTheUnion) {
  const double k = 0.3;
  const Compiled sharp = compile("sphere(radius: 0.5) translate([0.7, 0.2, 0]) { box(size: [0.5, 0.5, 0.5]) }");
  const Compiled smooth =
      compile("union(smooth: 0.3) { sphere(radius: 0.5) translate([0.7, 0.2, 0]) { box(size: [0.5, 0.5, 0.5]) } }");
  for (dvec3 p : randomPoints(3000, 1.5, 14)) {
    const double a = sphere(p, 0.5), b = box(p - dvec3(0.7, 0.2, 0), dvec3(0.5));
    const double u = std::min(a, b), s = smooth.distance(p);
    ASSERT_NEAR(sharp.distance(p), u, kExact);
    ASSERT_LE(s, u + kExact);
    ASSERT_GE(s, u - k / 4 - kExact);
    if (std::fabs(a - b) >= k) {
      ASSERT_NEAR(s, u, kExact);  // no blending far from the seam
    }
  }
}

TEST(Operators, SmoothIntersectAndSubtractMirrorTheUnion) {
  const double k = 0.2;
  const Compiled i = compile("intersect(smooth: 0.2) { box(size: [1, 1, 1]) sphere(radius: 0.65) }");
  const Compiled s = compile("subtract(smooth: 0.2) { box(size: [1, 1, 1]) sphere(radius: 0.65) }");
  for (dvec3 p : randomPoints(3000, 1.5, 15)) {
    const double a = box(p, dvec3(1)), b = sphere(p, 0.65);
    ASSERT_GE(i.distance(p), std::max(a, b) - kExact);
    ASSERT_LE(i.distance(p), std::max(a, b) + k / 4 + kExact);
    ASSERT_GE(s.distance(p), std::max(a, -b) - kExact);
    ASSERT_LE(s.distance(p), std::max(a, -b) + k / 4 + kExact);
  }
}

TEST(Operators, MorphIsTheLinearBlend) {
  const Compiled c = compile("morph(t: 0.3) { sphere(radius: 0.6) box(size: [1, 1, 1]) }");
  const Compiled timed = compile("morph(t: 0.5 + 0.5 * sin(time)) { sphere(radius: 0.6) box(size: [1, 1, 1]) }");
  for (dvec3 p : randomPoints(3000, 1.5, 16)) {
    ASSERT_NEAR(c.distance(p), 0.3 * sphere(p, 0.6) + 0.7 * box(p, dvec3(1)), kExact);
    const double t = 0.5 + 0.5 * std::sin(1.3);
    ASSERT_NEAR(timed.distance(p, 1.3), t * sphere(p, 0.6) + (1 - t) * box(p, dvec3(1)), kExact);
  }
}

TEST(Operators, TranslateByTimeFollowsTime) {
  const Compiled c = compile("translate([sin(time), 0, 2 * time]) { sphere(radius: 0.5) }");
  for (double time : {0.0, 0.4, 2.5})
    for (dvec3 p : randomPoints(500, 2, 17))
      ASSERT_NEAR(c.distance(p, time), sphere(p - dvec3(std::sin(time), 0, 2 * time), 0.5), kExact);
}

// Fusing constant transform chains into one affine map must not change the
// float64 field (beyond rounding).
TEST(Operators, TransformFusionLeavesDistancesUnchanged) {
  const char* bodies[] = {
      "translate([0.2, 0.1, 0]) { rotate(axis: [0, 0, 1], degrees: 30) { scale(1.5) {"
      " translate([0.1, 0, 0]) { rotate(euler: [10, 0, 45]) { box(size: [0.5, 0.3, 0.4], rounding: 0.05) } } } } }",
      "scale(0.5) { translate([1, 1, 1]) { scale(3) { torus(major: 0.3, minor: 0.1) } } }",
      "rotate(axis: [1, 0, 0], degrees: 90) { rotate(axis: [0, 1, 0], degrees: -90) { cone(radius: 0.5, height: 1) } }",
      "translate([0.5, 0, 0]) { union { sphere(radius: 0.3) rotate(euler: [0, 30, 0]) { translate([0.4, 0, 0]) {"
      " prism(size: 0.5, depth: 0.3) } } } }",
      "translate([0, 0, 0]) { rotate(axis: [0, 1, 0], degrees: 0) { scale(1) { hexprism(radius: 0.4, depth: 0.5) } } }",
      "repeat(cell: [2, 0, 0]) { rotate(axis: [0, 0, 1], degrees: 45) { translate([0.2, 0, 0]) { box(size: [0.5, 0.5, 0.5]) } } }",
      "scale(2) { elongate([0.2, 0, 0]) { translate([0.1, 0.1, 0]) { rotate(euler: [0, 0, 30]) { capsule(radius: 0.1, height: 0.4) } } } }",
  };
  for (const char* body : bodies) {
    const Compiled fused = compile(body, true), plain = compile(body, false);
    for (dvec3 p : randomPoints(3000, 2, 18))
      ASSERT_NEAR(fused.distance(p), plain.distance(p), 1e-12) << body;
  }
}

}  // namespace
}  // namespace sdfc
