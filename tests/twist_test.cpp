// twist(rate): the Lipschitz factor the analysis derives, (kR + sqrt((kR)^2
// + 4)) / 2, checked by sampling gradients of the raw twisted field (computed
// here from the child with its own rotation, not the compiler's) in the
// bounding cylinder: never above it, and close to it somewhere (so the issue's
// sqrt(1 + (kR)^2) is too small). And the field the compiler evaluates is a
// lower bound of the distance: along random rays, the first surface crossing
// found by fine root finding is never nearer than the field says.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "driver/compile.h"
#include "eval/evaluator.h"
#include "passes/deform.h"

namespace sdfc {
namespace {

using glm::dvec3;

constexpr double kPi = 3.14159265358979323846;

struct Compiled {
  CompiledScene scene;
  std::string messages;
  const ir::Node& twist() const { return *scene.scene.root->children[0]; }
};

Compiled compile(const std::string& body) {
  Diagnostics diags;
  Compiled c{checkSource("t.sdf", "scene { " + body + " }\n", {}, diags), ""};
  c.messages = diags.format();
  EXPECT_TRUE(c.scene.ok) << body << "\n" << c.messages;
  return c;
}

TEST(Twist, LipschitzBoundHoldsAndIsNearlyTight) {
  for (const double rate : {30.0, 90.0, 200.0}) {
    const std::string text = "twist(rate: " + std::to_string(rate) + ") { box(size: [1.6, 2, 0.6]) }";
    const Compiled c = compile(text);
    const ir::Node& t = c.twist();
    ASSERT_EQ(t.kind, ir::NodeKind::Twist);
    const double k = rate * kPi / 180, radius = std::sqrt(0.8 * 0.8 + 0.3 * 0.3);
    EXPECT_NEAR(t.deform_radius, radius, 1e-12);
    // The field is used out to 1/16 beyond the radius (the cylinder's distance
    // past that is never 0, where a march would stop): the factor is there.
    const double reach = radius * (1 + 1.0 / 16);
    EXPECT_NEAR(deformReach(t), reach, 1e-12);
    const double bound = (k * reach + std::sqrt(k * k * reach * reach + 4)) / 2;
    EXPECT_NEAR(t.deform_lipschitz, bound, 1e-12);
    // The map the child is read through: p turned back by k * y about y
    // (x' = cos a x + sin a z, z' = -sin a x + cos a z for a turn by a).
    auto map = [&](dvec3 p) {
      const double a = -k * p.y, cs = std::cos(a), sn = std::sin(a);
      return dvec3(cs * p.x + sn * p.z, p.y, -sn * p.x + cs * p.z);
    };
    const Evaluator eval(c.scene.scene);
    const ir::Node& child = *t.children[0];
    auto raw = [&](dvec3 p) { return eval.evalNode(child, map(p), -1).distance; };
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<double> u(-1, 1);
    double gradient = 0, stretch = 0;
    const double h = 1e-6;
    for (int i = 0; i < 40000; ++i) {
      const dvec3 p(u(rng) * reach, u(rng) * 1.5, u(rng) * reach);
      if (p.x * p.x + p.z * p.z > reach * reach) continue;
      // The raw field's gradient (the box's is axis-aligned in q, so it
      // rarely meets the worst direction) ...
      dvec3 g;
      for (int a = 0; a < 3; ++a) {
        dvec3 e(0);
        e[a] = h;
        g[a] = (raw(p + e) - raw(p - e)) / (2 * h);
      }
      gradient = std::max(gradient, glm::length(g));
      // ... and the map's stretch along a random direction, which meets it.
      const dvec3 v = glm::normalize(dvec3(u(rng), u(rng), u(rng)));
      stretch = std::max(stretch, glm::length(map(p + v * h) - map(p - v * h)) / (2 * h));
    }
    std::printf("twist rate %g: kR %.4f, bound %.6f, sampled stretch %.6f, field |grad| %.6f, sqrt(1 + (kR)^2) %.6f\n",
                rate, k * radius, bound, stretch, gradient, std::sqrt(1 + k * k * radius * radius));
    EXPECT_LE(gradient, bound * (1 + 1e-6)) << text;
    EXPECT_LE(stretch, bound * (1 + 1e-6)) << text;
    EXPECT_GT(stretch, 0.97 * bound) << text;  // the bound is close to tight ...
    EXPECT_GT(stretch, std::sqrt(1 + k * k * radius * radius) * 1.01) << text;  // ... and the too small
  }
}

TEST(Twist, NoRayPassesThroughTheSurface) {
  const Compiled c = compile("twist(rate: 120) { box(size: [1.6, 2, 0.4]) }");
  EXPECT_NE(c.messages.find("'twist' gives a distance bound"), std::string::npos) << c.messages;
  const Evaluator eval(c.scene.scene);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  int checked = 0;
  for (int i = 0; i < 400; ++i) {
    const dvec3 origin(u(rng) * 2.5, u(rng) * 2, u(rng) * 2.5);
    const dvec3 dir = glm::normalize(dvec3(u(rng), u(rng), u(rng)));
    const double d = eval.distance(origin);
    if (d <= 0) continue;
    // The first sign change along the ray, in steps of 1e-3 out to 6.
    double hit = 1e300;
    for (double s = 0; s < 6; s += 1e-3)
      if (eval.distance(origin + dir * s) < 0) {
        hit = s;
        break;
      }
    EXPECT_LE(d, hit + 1e-3) << "a step of " << d << " would cross the surface at " << hit;
    ++checked;
  }
  EXPECT_GT(checked, 200);
}

TEST(Twist, ZeroRateIsTheShapeAndUnboundedShapesAreRefused) {
  const Compiled c = compile("twist(rate: 0) { box(size: [1, 1, 1]) }");
  const Evaluator eval(c.scene.scene);
  for (const dvec3& p : {dvec3(0.2, 0.1, 0.3), dvec3(0.4, -0.2, 0.1), dvec3(0.1, 0.45, -0.2)})
    EXPECT_NEAR(eval.distance(p), -std::min({0.5 - std::fabs(p.x), 0.5 - std::fabs(p.y), 0.5 - std::fabs(p.z)}), 1e-12);
  Diagnostics diags;
  // Diagnostics point into the compiled scene's source: keep it while formatting.
  const CompiledScene refused = checkSource("t.sdf", "scene { twist(rate: 10) { plane() } }\n", {}, diags);
  EXPECT_FALSE(refused.ok);
  EXPECT_EQ(diags.format(),
            "t.sdf:1:9: warning: 'twist' gives a distance bound, not an exact distance (marching divides it by the "
            "twist's stretch) [-Wbound]\n"
            "scene { twist(rate: 10) { plane() } }\n"
            "        ^~~~~\n"
            "t.sdf:1:9: error: 'twist' needs a bounded shape: its stretch grows with the distance from the axis, "
            "so an unbounded shape has no safe step\n"
            "scene { twist(rate: 10) { plane() } }\n"
            "        ^~~~~~~~~~~~~~~~~~~~~~~~~~~\n");
}

}  // namespace
}  // namespace sdfc
