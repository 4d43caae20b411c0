// Issue 49: `repeat` of a shape far off its cell's centre, or wider than its
// cell, and `repeat_polar` of a shape past its sector. The float64 field must
// be the minimum over every copy (brute force): never above it and never of
// the other sign, so no copy vanishes. GpuEquivalence.EveryOperator checks
// that the emitted GLSL agrees with the evaluator on such cases.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <sstream>

#include "driver/compile.h"
#include "eval/evaluator.h"

namespace sdfc {
namespace {

using glm::dvec3;

ir::Scene compileScene(const std::string& text) {
  CompileOptions options;
  options.produce_spirv = false;
  options.emit.with_kernel = false;
  // The points probed are world points: keep the scene there (a camera
  // standing near the copies moves it to the camera's frame, passes/rebase.cpp).
  options.camera_frame = false;
  Diagnostics diags;
  CompiledScene c = compileSource("repeat.sdf", text, options, diags);
  EXPECT_TRUE(c.ok) << diags.format() << text;
  return std::move(c.scene);
}

struct Tally {
  int points = 0, sign_errors = 0, above = 0;
  double worst_ratio = 0;  // field / true distance, outside
};

// The shapes repeated, each about 0.3 to 0.8 across.
const char* kShapes[] = {
    "sphere(radius: 0.3)",
    "box(size: [0.5, 0.3, 0.4])",
    "rotate(euler: [30, 20, 0]) { torus(major: 0.3, minor: 0.1) }",
    "capsule(radius: 0.15, height: 0.4)",
    "union { sphere(radius: 0.2) translate([0.3, 0.2, 0]) { box(size: [0.2, 0.2, 0.2]) } }",
};

void compare(const std::string& repeated, const std::string& one_copy_at, const std::vector<dvec3>& copies,
             const dvec3& lo, const dvec3& hi, unsigned seed, Tally& t) {
  const ir::Scene scene = compileScene("scene { " + repeated + " }");
  const ir::Scene copy = compileScene("scene { " + one_copy_at + " }");
  const Evaluator field(scene), one(copy);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  for (int i = 0; i < 2000; ++i) {
    const dvec3 p = lo + (hi - lo) * dvec3(u(rng), u(rng), u(rng));
    double truth = INFINITY;
    for (const dvec3& c : copies) truth = std::min(truth, one.distance(p - c));
    const double f = field.distance(p);
    ++t.points;
    if ((truth < -1e-9 && f > 1e-9) || (truth > 1e-9 && f < -1e-9)) ++t.sign_errors;
    if (f > truth + 1e-9 * (1 + std::fabs(truth))) {
      if (t.above++ < 3 && std::getenv("SDFC_DEBUG_POINTS"))
        std::printf("%s at (%g, %g, %g): field %g, brute force %g\n", repeated.c_str(), p.x, p.y, p.z, f, truth);
    }
    if (truth > 1e-3) t.worst_ratio = std::max(t.worst_ratio, f / truth);
  }
}

std::string vec(const dvec3& v) {
  std::ostringstream s;
  s << "[" << v.x << ", " << v.y << ", " << v.z << "]";
  return s.str();
}

// Grid repeats: every shape, offsets from inside the cell to several cells
// away, cells narrower than the shape, limited and infinite counts.
TEST(RepeatReach, GridCopiesMatchBruteForce) {
  std::mt19937 rng(49);
  std::uniform_real_distribution<double> u(-1, 1);
  Tally t;
  int cases = 0;
  for (const char* shape : kShapes)
    for (double cell : {0.4, 1.0, 2.0})
      for (double far : {0.0, 0.7, 1.6, 3.3}) {
        const dvec3 offset(far * cell * u(rng) * 1.5, 0.3 * u(rng), far * cell * u(rng));
        const glm::ivec3 count(1 + int(4.5 + 4.5 * u(rng)), 0, 3);
        // x limited, y not repeated, z limited: every copy is listed.
        std::vector<dvec3> copies;
        for (int i = 0; i < count.x; ++i)
          for (int k = 0; k < count.z; ++k)
            copies.push_back({cell * (i - (count.x - 1) * 0.5), 0, cell * (k - (count.z - 1) * 0.5)});
        const std::string placed = "translate(" + vec(offset) + ") { " + shape + " }";
        const std::string repeated = "repeat(cell: [" + std::to_string(cell) + ", 0, " + std::to_string(cell) +
                                     "], count: [" + std::to_string(count.x) + ", 1, 3]) { " + placed + " }";
        const dvec3 reach = glm::abs(offset) + 1.0 + dvec3(count.x, 0, 3) * cell * 0.5;
        compare(repeated, placed, copies, -reach, reach, unsigned(cases), t);
        ++cases;
      }
  std::printf("[ repeat   ] %d cases, %d points: %d of the other sign, %d above the true distance, worst "
              "field / distance %.3g\n",
              cases, t.points, t.sign_errors, t.above, t.worst_ratio);
  EXPECT_EQ(t.sign_errors, 0);
  EXPECT_EQ(t.above, 0);
}

// An infinite repeat of a shape several cells off its centre: the copies
// near the sampled box stand in for all of them.
TEST(RepeatReach, InfiniteRepeatFarOffCentre) {
  Tally t;
  int cases = 0;
  for (const char* shape : kShapes)
    for (double off : {0.9, 2.6, 7.3}) {
      const double cell = 1.0;
      const dvec3 offset(off, 0.1, -0.4 * off);
      std::vector<dvec3> copies;
      for (int i = -20; i <= 20; ++i)
        for (int k = -20; k <= 20; ++k) copies.push_back({cell * i, 0, cell * k});
      const std::string placed = "translate(" + vec(offset) + ") { " + shape + " }";
      compare("repeat(cell: [1, 0, 1]) { " + placed + " }", placed, copies, dvec3(-3, -1, -3), dvec3(3, 1, 3),
              unsigned(100 + cases), t);
      ++cases;
    }
  std::printf("[ repeat   ] infinite, %d cases, %d points: %d of the other sign, %d above the true distance\n", cases,
              t.points, t.sign_errors, t.above);
  EXPECT_EQ(t.sign_errors, 0);
  EXPECT_EQ(t.above, 0);
}

// Polar repeats: shapes inside, across and well past their sector, and
// shapes that hold the axis.
TEST(RepeatReach, PolarCopiesMatchBruteForce) {
  Tally t;
  int cases = 0;
  for (const char* shape : kShapes)
    for (int count : {3, 5, 8, 16})
      for (dvec3 offset : {dvec3(1.2, 0, 0), dvec3(0.9, 0.1, 0.5), dvec3(-0.6, 0, 0.9), dvec3(0.1, 0, -0.15),
                           dvec3(0.5, 0, -1.1)}) {
        const std::string placed = "translate(" + vec(offset) + ") { " + shape + " }";
        // Brute force: each copy is the shape turned by k 2 pi / count about y.
        const ir::Scene scene = compileScene("scene { repeat_polar(count: " + std::to_string(count) + ") { " +
                                             placed + " } }");
        const ir::Scene copy = compileScene("scene { " + placed + " }");
        const Evaluator field(scene), one(copy);
        std::mt19937 rng{unsigned(cases)};
        std::uniform_real_distribution<double> u(-2, 2);
        for (int i = 0; i < 2000; ++i) {
          const dvec3 p(u(rng), 0.3 * u(rng), u(rng));
          double truth = INFINITY;
          for (int k = 0; k < count; ++k) {
            const double a = 2 * M_PI * k / count, c = std::cos(a), s = std::sin(a);
            // The copy turned by a: its point p is the shape's point turned by -a.
            truth = std::min(truth, one.distance({c * p.x + s * p.z, p.y, c * p.z - s * p.x}));
          }
          const double f = field.distance(p);
          ++t.points;
          if ((truth < -1e-9 && f > 1e-9) || (truth > 1e-9 && f < -1e-9)) ++t.sign_errors;
          if (f > truth + 1e-9 * (1 + std::fabs(truth))) {
            if (t.above++ < 3 && std::getenv("SDFC_DEBUG_POINTS"))
              std::printf("polar %d %s at (%g, %g, %g): field %g, brute force %g\n", count, placed.c_str(), p.x, p.y,
                          p.z, f, truth);
          }
          if (truth > 1e-3) t.worst_ratio = std::max(t.worst_ratio, f / truth);
        }
        ++cases;
      }
  std::printf("[ polar    ] %d cases, %d points: %d of the other sign, %d above the true distance, worst field / "
              "distance %.3g\n",
              cases, t.points, t.sign_errors, t.above, t.worst_ratio);
  EXPECT_EQ(t.sign_errors, 0);
  EXPECT_EQ(t.above, 0);
}

}  // namespace
}  // namespace sdfc
