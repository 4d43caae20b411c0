// 2D profiles (circle, rect, hexagon, polygon) and the solids made of them
// (extrude, revolve), in the float64 evaluator, against independent closed
// forms: the existing 3D primitives they must equal, and brute force over
// densely sampled boundaries with a winding-number inside test. Plus the
// checker's rules (a profile only in extrude/revolve, simple polygons) pinned
// as text.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "driver/compile.h"
#include "eval/evaluator.h"

namespace sdfc {
namespace {

using glm::dvec2;
using glm::dvec3;

constexpr double kExact = 1e-12;
constexpr double kPi = 3.14159265358979323846;

struct Compiled {
  CompiledScene scene;
  double distance(dvec3 p) const { return Evaluator(scene.scene).distance(p); }
  bool exact() const { return scene.scene.root->exact; }
};

Compiled compile(const std::string& body, std::string* messages = nullptr) {
  Diagnostics diags;
  Compiled c{checkSource("t.sdf", "scene { " + body + " }\n", {}, diags)};
  EXPECT_TRUE(c.scene.ok) << body << "\n" << diags.format();
  if (messages) *messages = diags.format();
  return c;
}

std::vector<dvec3> randomPoints(int n, double extent, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-extent, extent);
  std::vector<dvec3> pts;
  for (int i = 0; i < n; ++i) pts.push_back({u(rng), u(rng), u(rng)});
  return pts;
}

void expectSame(const std::string& a, const std::string& b, double extent = 3) {
  const Compiled x = compile(a), y = compile(b);
  for (const dvec3& p : randomPoints(4000, extent, 7)) {
    ASSERT_NEAR(x.distance(p), y.distance(p), kExact) << a << " vs " << b << " at " << p.x << ", " << p.y << ", " << p.z;
  }
}

TEST(Profiles, ExtrudeAndRevolveEqualThePrimitives) {
  // The closed forms, and hexprism / prism / cylinder / sphere.
  expectSame("revolve(offset: 2) { circle(radius: 0.5) }", "torus(major: 2, minor: 0.5)");
  expectSame("extrude(depth: 2) { rect(size: [1, 3]) }", "box(size: [1, 3, 2])");
  expectSame("extrude(depth: 1.5) { hexagon(radius: 0.7) }", "hexprism(radius: 0.7, depth: 1.5)");
  // prism: side 1.2, centroid at the origin, apex up.
  const double h = 1.2 * std::sqrt(3.0) / 2;
  char tri[200];
  std::snprintf(tri, sizeof tri, "extrude(depth: 0.5) { polygon(points: [[-0.6, %.17g], [0.6, %.17g], [0, %.17g]]) }",
                -h / 3, -h / 3, 2 * h / 3);
  expectSame(tri, "prism(size: 1.2, depth: 0.5)");
  expectSame("revolve { rect(size: [2, 1]) }", "cylinder(radius: 1, height: 1)");
  expectSame("revolve { circle(radius: 1) }", "sphere(radius: 1)");
  expectSame("extrude(depth: 1) { polygon(points: [[-1, -0.5], [1, -0.5], [1, 0.5], [-1, 0.5]]) }",
             "box(size: [2, 1, 1])");
  // Planar moves and offsets of a profile are the same moves of the solid.
  expectSame("extrude(depth: 1) { translate([0.5, -0.2]) { rotate(axis: [0, 0, 1], degrees: 30) { rect(size: [1, 0.4]) } } }",
             "translate([0.5, -0.2, 0]) { rotate(axis: [0, 0, 1], degrees: 30) { box(size: [1, 0.4, 1]) } }");
  expectSame("revolve(offset: 1) { round(radius: 0.1) { rect(size: [0.4, 0.6]) } }",
             "revolve(offset: 1) { rect(size: [0.6, 0.8], rounding: 0.1) }");
  for (const char* s : {"revolve(offset: 2) { circle(radius: 0.5) }", "revolve { circle(radius: 1) }",
                        "extrude(depth: 1) { polygon(points: [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]) }"})
    EXPECT_TRUE(compile(s).exact()) << s;
}

// The signed distance to a polygon by brute force: the nearest of many points
// along its edges, signed by the winding number (not the even-odd rule the
// compiler uses; the two agree on simple polygons).
double bruteForcePolygon(const std::vector<dvec2>& v, dvec2 p) {
  double best = 1e300;
  for (size_t i = 0; i < v.size(); ++i) {
    const dvec2 a = v[i], b = v[(i + 1) % v.size()];
    const int steps = 4000;
    for (int k = 0; k <= steps; ++k) best = std::min(best, glm::length(p - (a + (b - a) * (double(k) / steps))));
  }
  // Sum of the angles each edge turns, wrapped per edge.
  double turn = 0;
  for (size_t i = 0; i < v.size(); ++i) {
    const dvec2 a = v[i] - p, b = v[(i + 1) % v.size()] - p;
    turn += std::atan2(a.x * b.y - a.y * b.x, glm::dot(a, b));
  }
  return std::fabs(turn) > kPi ? -best : best;
}

TEST(Profiles, PolygonAgainstBruteForce) {
  // A concave star and an L, either orientation.
  std::vector<dvec2> star;
  for (int i = 0; i < 10; ++i) {
    const double a = kPi / 2 + i * kPi / 5, r = i % 2 ? 0.4 : 1.0;
    star.push_back({r * std::cos(a), r * std::sin(a)});
  }
  const std::vector<dvec2> ell = {{0, 0}, {0, 2}, {1, 2}, {1, 1}, {2, 1}, {2, 0}};  // clockwise
  for (const auto& poly : {star, ell}) {
    std::string text = "extrude(depth: 1) { polygon(points: [";
    char buf[80];
    for (size_t i = 0; i < poly.size(); ++i) {
      std::snprintf(buf, sizeof buf, "%s[%.17g, %.17g]", i ? ", " : "", poly[i].x, poly[i].y);
      text += buf;
    }
    text += "]) }";
    const Compiled c = compile(text);
    int inside = 0;
    for (const dvec3& p : randomPoints(300, 2.2, 11)) {
      const dvec3 q(p.x, p.y, 0);  // on the mid-plane the solid's distance is the profile's
      const double want = bruteForcePolygon(poly, dvec2(q.x, q.y));
      inside += want < 0;
      ASSERT_NEAR(c.distance(q), want, 1e-3) << text << " at " << q.x << ", " << q.y;
    }
    EXPECT_GT(inside, 10);
  }
}

TEST(Profiles, RoundedRectAgainstBruteForce) {
  // Boundary: four segments and four quarter circles of radius 0.25.
  const Compiled c = compile("extrude(depth: 2) { rect(size: [1.6, 1], rounding: 0.25) }");
  const dvec2 h(0.8, 0.5);
  const double r = 0.25;
  std::vector<dvec2> boundary;
  for (int k = 0; k <= 20000; ++k) {
    const double a = 2 * kPi * k / 20000;
    const dvec2 dir(std::cos(a), std::sin(a));
    const dvec2 centre(dir.x > 0 ? h.x - r : -(h.x - r), dir.y > 0 ? h.y - r : -(h.y - r));
    boundary.push_back(centre + r * dir);
    // The straight parts stop where the arcs begin.
    const double t = double(k) / 20000;
    const dvec2 in = h - r;
    boundary.push_back({-in.x + 2 * in.x * t, h.y});
    boundary.push_back({-in.x + 2 * in.x * t, -h.y});
    boundary.push_back({h.x, -in.y + 2 * in.y * t});
    boundary.push_back({-h.x, -in.y + 2 * in.y * t});
  }
  for (const dvec3& p : randomPoints(200, 1.3, 3)) {
    double best = 1e300;
    for (const dvec2& b : boundary) best = std::min(best, glm::length(dvec2(p.x, p.y) - b));
    const dvec2 q = glm::abs(dvec2(p.x, p.y)) - (h - r);
    const bool inside = (q.x <= 0 && std::fabs(p.y) < h.y) || (q.y <= 0 && std::fabs(p.x) < h.x) ||
                        glm::length(glm::max(q, dvec2(0))) < r;
    ASSERT_NEAR(c.distance({p.x, p.y, 0}), inside ? -best : best, 2e-4);
  }
}

TEST(Profiles, RevolveAcrossTheAxisIsABoundAndWarns) {
  std::string messages;
  const Compiled c = compile("revolve(offset: 0.2) { circle(radius: 0.5) }", &messages);
  EXPECT_FALSE(c.exact());
  EXPECT_NE(messages.find("reaches across the axis"), std::string::npos) << messages;
  // A lower bound outside: never above the distance to the true solid, the
  // revolution of the circle's part at x >= -0.2 (a spindle torus); its
  // meridian section is the two mirrored discs clipped at the axis.
  for (const dvec3& p : randomPoints(2000, 1.5, 5)) {
    const double rr = std::sqrt(p.x * p.x + p.z * p.z);
    double best = 1e300;
    bool inside = false;
    for (int k = 0; k < 4000; ++k) {
      const double a = 2 * kPi * k / 4000;
      for (double s : {1.0, -1.0}) {
        // The disc centred at s * 0.2, clipped to the half on its own side.
        const dvec2 b(s * 0.2 + 0.5 * std::cos(a), 0.5 * std::sin(a));
        if (b.x * s >= 0) best = std::min(best, glm::length(dvec2(rr, p.y) - b));
      }
    }
    // The axis segment where the two discs overlap bounds nothing (inside both).
    inside = glm::length(dvec2(rr - 0.2, p.y)) < 0.5;
    if (!inside) {
      EXPECT_LE(c.distance(p), best + 1e-3);
    }
  }
  // Offset 0 with a symmetric profile is exact and silent.
  compile("revolve { translate([0, 0.3]) { hexagon(radius: 0.5) } }", &messages);
  EXPECT_EQ(messages, "");
}

std::string diagnosticsFor(const std::string& text) {
  Diagnostics diags;
  const CompiledScene compiled = checkSource("t.sdf", text, {}, diags);
  return diags.format();
}

TEST(Profiles, Diagnostics) {
  const std::pair<const char*, const char*> cases[] = {
      {"scene { circle(radius: 1) }\n",
       "t.sdf:1:9: error: the scene holds shapes, not a 2D profile (only extrude and revolve take one)\n"
       "scene { circle(radius: 1) }\n"
       "        ^~~~~~~~~~~~~~~~~\n"},
      {"scene { extrude(depth: 1) { sphere(radius: 1) } }\n",
       "t.sdf:1:29: error: 'extrude' takes 2D profiles in its block (circle, rect, polygon, hexagon), not a shape\n"
       "scene { extrude(depth: 1) { sphere(radius: 1) } }\n"
       "                            ^~~~~~~~~~~~~~~~~\n"},
      {"scene { extrude(depth: 1) { union { circle(radius: 1) sphere(radius: 1) } } }\n",
       "t.sdf:1:55: error: 'union' cannot mix 2D profiles and shapes in one block; extrude or revolve the profile first\n"
       "scene { extrude(depth: 1) { union { circle(radius: 1) sphere(radius: 1) } } }\n"
       "                                                      ^~~~~~~~~~~~~~~~~\n"},
      {"scene { repeat(cell: [2, 0, 0]) { rect(size: [1, 1]) } }\n",
       "t.sdf:1:35: error: 'repeat' does not take a 2D profile; extrude or revolve it first\n"
       "scene { repeat(cell: [2, 0, 0]) { rect(size: [1, 1]) } }\n"
       "                                  ^~~~~~~~~~~~~~~~~~\n"},
      {"scene { instances(positions: [[0, 0, 0]]) { circle(radius: 1) } }\n",
       "t.sdf:1:45: error: 'instances' expects shapes in its block, not a 2D profile (only extrude and revolve take one)\n"
       "scene { instances(positions: [[0, 0, 0]]) { circle(radius: 1) } }\n"
       "                                            ^~~~~~~~~~~~~~~~~\n"},
      {"scene { extrude(depth: 1) { polygon(points: [[0, 0], [1, 0]]) } }\n",
       "t.sdf:1:45: error: a polygon needs at least 3 points, got 2\n"
       "scene { extrude(depth: 1) { polygon(points: [[0, 0], [1, 0]]) } }\n"
       "                                            ^~~~~~~~~~~~~~~~\n"},
      {"scene { extrude(depth: 1) { polygon([[0, 0], [1, 1], [1, 0], [0, 1]]) } }\n",
       "t.sdf:1:37: error: edges 1 and 3 cross; the polygon must not intersect itself\n"
       "scene { extrude(depth: 1) { polygon([[0, 0], [1, 1], [1, 0], [0, 1]]) } }\n"
       "                                    ^~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~\n"},
      {"scene { extrude(depth: 1) { polygon([[0, 0], [1, 0], [0, 0], [0, 1]]) } }\n",
       "t.sdf:1:37: error: points 1 and 3 are the same point\n"
       "scene { extrude(depth: 1) { polygon([[0, 0], [1, 0], [0, 0], [0, 1]]) } }\n"
       "                                    ^~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~\n"},
      {"scene { extrude(depth: 1) { polygon([[0, 0], [1, 0], [2, 0]]) } }\n",
       "t.sdf:1:37: error: edges 1 and 3 overlap\n"
       "scene { extrude(depth: 1) { polygon([[0, 0], [1, 0], [2, 0]]) } }\n"
       "                                    ^~~~~~~~~~~~~~~~~~~~~~~~\n"},
      {"scene { extrude(depth: 1) { polygon([[0, 0], [1, 0, 2], [0, 1]]) } }\n",
       "t.sdf:1:46: error: each point of a polygon must be a constant [x, y], not a 3-vector\n"
       "scene { extrude(depth: 1) { polygon([[0, 0], [1, 0, 2], [0, 1]]) } }\n"
       "                                             ^~~~~~~~~\n"},
      {"scene { extrude(depth: 1) { rect(size: [1, 2], rounding: 0.6) } }\n",
       "t.sdf:1:29: error: rect 'rounding' (0.6) must be at most half the smaller side (0.5)\n"
       "scene { extrude(depth: 1) { rect(size: [1, 2], rounding: 0.6) } }\n"
       "                            ^~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~\n"},
      {"scene { extrude(depth: 1) { rect(size: [1, 2, 3]) } }\n",
       "t.sdf:1:40: error: 'size' of 'rect' must be a 2-vector like [x, y], not a 3-vector\n"
       "scene { extrude(depth: 1) { rect(size: [1, 2, 3]) } }\n"
       "                                       ^~~~~~~~~\n"},
      {"scene { extrude(depth: 1) { translate([0, 0, 1]) { circle(radius: 1) } } }\n",
       "t.sdf:1:39: error: a 2D profile moves in its plane: 'offset' must be [x, y]\n"
       "scene { extrude(depth: 1) { translate([0, 0, 1]) { circle(radius: 1) } } }\n"
       "                                      ^~~~~~~~~\n"},
      {"scene { revolve { rotate(axis: [1, 0, 0], degrees: 90) { circle(radius: 1) } } }\n",
       "t.sdf:1:19: error: a 2D profile turns in its plane: rotate it about the z axis (axis: [0, 0, 1]), or rotate the extruded shape\n"
       "scene { revolve { rotate(axis: [1, 0, 0], degrees: 90) { circle(radius: 1) } } }\n"
       "                  ^~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~\n"},
      {"scene { twist(rate: 10) { circle(radius: 1) } }\n",
       "t.sdf:1:27: error: 'twist' does not take a 2D profile; extrude or revolve it first\n"
       "scene { twist(rate: 10) { circle(radius: 1) } }\n"
       "                          ^~~~~~~~~~~~~~~~~\n"},
      {"scene { revolve(offset: 0.2) { circle(radius: 0.5) } }\n",
       "t.sdf:1:9: warning: the profile of 'revolve' reaches across the axis (x < -offset = -0.2); that part is not revolved, and the distance is only a bound (move the profile to x >= -offset) [-Wbound]\n"
       "scene { revolve(offset: 0.2) { circle(radius: 0.5) } }\n"
       "        ^~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~\n"},
  };
  for (const auto& [input, expected] : cases) {
    const std::string actual = diagnosticsFor(input);
    EXPECT_EQ(actual, expected) << "input: " << input;
  }
}

TEST(Profiles, NeverInstanced) {
  // Many copies of one profile in a union stay code: instancing places
  // shapes in space, and a profile lives at z = 0 under its extrude.
  std::string text = "scene { extrude(depth: 0.2) { union {";
  for (int i = 0; i < 40; ++i) text += " translate([" + std::to_string(i) + ", 0]) { circle(radius: 0.3) }";
  text += " } } }\n";
  Diagnostics diags;
  CompileOptions options;
  options.produce_spirv = false;
  CompiledScene c = compileSource("t.sdf", text, options, diags);
  ASSERT_TRUE(c.ok) << diags.format();
  EXPECT_EQ(c.emitted.glsl.find("sd_data"), std::string::npos);
  EXPECT_EQ(c.emitted.stats.instance_sets, 0);
  EXPECT_NEAR(Evaluator(c.scene).distance({7, 0, 0}), -0.1, kExact);
}

}  // namespace
}  // namespace sdfc
