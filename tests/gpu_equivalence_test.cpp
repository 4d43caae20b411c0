// The generated GLSL, run on the Vulkan device (lavapipe here), against the
// float64 evaluator: every primitive, every operator and every example scene,
// each at 4096 pseudo-random points, with bounding volumes on and off and with
// transform fusion on and off.
//
// The float32 bound. Let S be the scene's scale: the largest coordinate
// magnitude of the sample box and of the scene's finite bounds (>= 1). The GPU
// evaluates at the float32 point it read back, so the input is exact; what
// differs is (1) every constant rounded to float32 (relative 2^-24, absolute
// <= 2^-24 S) and (2) every operation rounded (+, -, *, sqrt correctly rounded
// on lavapipe; Vulkan allows 2.5 ulp for division; relative 2^-24 each). Every
// intermediate is a coordinate, size or distance of magnitude <= ~2 S, and
// every stage is 1-Lipschitz in its inputs (transforms are isometries or exact
// scalings, min/max/smooth-min are 1-Lipschitz, primitives are distances), so
// the errors add along the longest chain of dependent operations. That chain
// is ~15 operations per primitive plus ~5 per operator level (rotation adds
// the sin/cos error, 2^-22 relative on lavapipe, times |p| <= S); our deepest
// scenes have about 30. Hence
//     |d_gpu - d_cpu| <= 64 * 2^-23 * S   (30 ops * 2 S * 2^-24 * margin 2),
// which the test asserts; measured worst cases are printed per scene.
// The unbounded code must meet that bound against the evaluator everywhere.
// Bounding-volume code may, far from a subtree's box, return the box distance
// instead of the subtree's (a lower bound). So the bounded result is checked
// against the unbounded one: never above it (+eps), same sign, and equal
// wherever it is below the smallest "far" margin the emitter used (read from
// the emitted code), i.e. in the band near surfaces the marcher resolves.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "driver/compile.h"
#include "eval/evaluator.h"
#include "gpu_points.h"
#include "vulkan_context.h"

namespace sdfc {
namespace {

using glm::dvec3;

constexpr double kUlp = 1.0 / 8388608.0;  // 2^-23
constexpr double kBoundUlps = 64;
constexpr float kTime = 0.7f;

struct SceneCase {
  std::string name;
  std::string text;
};

std::vector<SceneCase> primitiveScenes() {
  return {
      {"sphere", "scene { sphere(radius: 0.8) }"},
      {"box", "scene { box(size: [1.2, 0.7, 0.9]) }"},
      {"rounded box", "scene { box(size: [1.2, 0.7, 0.9], rounding: 0.15) }"},
      {"torus", "scene { torus(major: 0.9, minor: 0.3) }"},
      {"cylinder", "scene { cylinder(radius: 0.5, height: 1.4) }"},
      {"cone", "scene { cone(radius: 0.6, height: 1.1) }"},
      {"plane", "scene { plane(normal: [0.3, 1, -0.5], offset: 0.2) }"},
      {"capsule", "scene { capsule(radius: 0.35, height: 1) }"},
      {"prism", "scene { prism(size: 1, depth: 0.6) }"},
      {"hexprism", "scene { hexprism(radius: 0.5, depth: 0.8) }"},
      {"menger", "scene { menger(level: 3, size: 1.5) }"},
      {"octahedron", "scene { octahedron(radius: 0.9) }"},
      {"pyramid", "scene { pyramid(size: 1.2, height: 0.9) }"},
      {"round cone", "scene { round_cone(bottom: 0.5, top: 0.2, height: 0.8) }"},
      {"round cone, top larger", "scene { round_cone(bottom: 0.15, top: 0.4, height: 0.6) }"},
      {"ellipsoid", "scene { ellipsoid(radii: [0.9, 0.5, 0.7]) }"},
      // 2D profiles, as the solids extrude and revolve make of them.
      {"extruded circle", "scene { extrude(depth: 0.6) { circle(radius: 0.7) } }"},
      {"extruded rounded rect", "scene { extrude(depth: 1.1) { rect(size: [1.4, 0.8], rounding: 0.2) } }"},
      {"revolved hexagon", "scene { revolve(offset: 0.6) { hexagon(radius: 0.3) } }"},
      {"extruded polygon",
       "scene { extrude(depth: 0.5) { polygon(points: [[0, 0.9], [0.25, 0.3], [0.9, 0.2], [0.35, -0.2], [0.6, -0.8], "
       "[0, -0.4], [-0.6, -0.8], [-0.35, -0.2], [-0.9, 0.2], [-0.25, 0.3]]) } }"},
      {"revolved polygon", "scene { revolve { polygon([[0, -0.6], [0.7, -0.6], [0.3, 0], [0.5, 0.6], [0, 0.6]]) } }"},
  };
}

std::vector<SceneCase> operatorScenes() {
  return {
      {"union", "scene { sphere(radius: 0.5) translate([1.2, 0, 0]) { box(size: [0.6, 0.6, 0.6]) } }"},
      {"smooth union",
       "scene { union(smooth: 0.3) { sphere(radius: 0.5) translate([0.7, 0.2, 0]) { torus(major: 0.4, minor: 0.15) } } }"},
      {"smooth intersect",
       "scene { intersect(smooth: 0.1) { box(size: [1, 1, 1]) sphere(radius: 0.65) } }"},
      {"smooth subtract",
       "scene { subtract(smooth: 0.05) { box(size: [1, 1, 1], rounding: 0.1) cylinder(radius: 0.3, height: 2) } }"},
      {"translate by time", "scene { translate([sin(time), 0.2, -0.1]) { cone(radius: 0.4, height: 0.8) } }"},
      {"rotate axis", "scene { rotate(axis: [1, 2, 0.5], degrees: 37) { box(size: [1.4, 0.4, 0.8]) } }"},
      {"rotate euler", "scene { rotate(euler: [20, -35, 70]) { prism(size: 1, depth: 0.5) } }"},
      {"rotate by time", "scene { rotate(axis: [0, 1, 0], degrees: 90 * time) { hexprism(radius: 0.4, depth: 1) } }"},
      {"uniform scale", "scene { scale(2.5) { capsule(radius: 0.2, height: 0.5) } }"},
      {"non-uniform scale", "scene { scale([1, 2, 0.5]) { sphere(radius: 0.5) } }"},
      {"reflect",
       "scene { reflect(normal: [1, 1, 0], offset: 0.1) { translate([0.6, 0, 0.2]) { sphere(radius: 0.3) } } }"},
      {"repeat infinite overlapping",
       "scene { repeat(cell: [1, 0, 1]) { translate([0.3, 0, 0]) { box(size: [0.9, 0.5, 0.4]) } } }"},
      {"repeat limited", "scene { repeat(cell: [0.8, 0.8, 0], count: [3, 2, 0]) { sphere(radius: 0.5) } }"},
      {"repeat off-centre inside its cell",
       "scene { repeat(cell: [2, 0, 1.5]) { translate([0.75, 0.3, -0.4]) { box(size: [0.5, 0.5, 0.5]) } } }"},
      {"elongate", "scene { elongate([0.6, 0, 0.3]) { torus(major: 0.5, minor: 0.15) } }"},
      {"morph", "scene { morph(t: 0.3) { sphere(radius: 0.6) box(size: [1, 1, 1]) } }"},
      {"round", "scene { round(radius: 0.2) { box(size: [1, 0.6, 0.8]) } }"},
      {"round by time", "scene { round(radius: 0.1 + 0.1 * sin(time)) { octahedron(radius: 0.6) } }"},
      {"profile csg",
       "scene { revolve(offset: 0.5) { subtract(smooth: 0.05) { union { rect(size: [0.4, 1]) translate([0.2, 0.3]) {\n"
       "  rotate(axis: [0, 0, 1], degrees: 30) { circle(radius: 0.25) } } } round(radius: 0.02) { hexagon(radius: 0.1) } } } }"},
      {"profile by time", "scene { extrude(depth: 0.5 + 0.2 * sin(time)) { shell(thickness: 0.1) { circle(radius: 0.6) } } }"},
      {"twist", "scene { twist(rate: 90) { box(size: [1.2, 1.6, 0.4]) } }"},
      {"twist by time", "scene { twist(rate: 60 * sin(time)) { translate([0.2, 0, 0]) { hexprism(radius: 0.3, depth: 1) } } }"},
      {"bend", "scene { bend(rate: 40) { box(size: [1.6, 0.3, 0.4]) } }"},
      {"bend by time", "scene { bend(rate: 30 + 20 * sin(time)) { translate([0, 0, 0.2]) { capsule(radius: 0.15, height: 1) } } }"},
      {"displace", "scene { displace(amplitude: 0.08, scale: 3, octaves: 3) { sphere(radius: 0.7) } }"},
      {"displace by time", "scene { displace(amplitude: 0.05 * sin(time), scale: 2 + cos(time)) { box(size: [1, 0.8, 0.6]) } }"},
      {"repeat_polar", "scene { repeat_polar(count: 6) { translate([0.7, 0, 0]) { box(size: [0.3, 0.5, 0.2]) } } }"},
      {"repeat_polar crossing", "scene { repeat_polar(count: 5) { translate([0.5, 0.1, 0.3]) { sphere(radius: 0.3) } } }"},
      // Issue 49: copies far off the cell's centre, wider than the cell, past
      // the sector, or around the axis: more cells and sectors tried.
      {"repeat far off centre",
       "scene { repeat(cell: [1, 0, 1]) { translate([2.6, 0.1, -1.3]) { rotate(euler: [30, 20, 0]) { "
       "torus(major: 0.3, minor: 0.1) } } } }"},
      {"repeat wider than its cell",
       "scene { repeat(cell: [0.4, 0, 0.5], count: [6, 0, 3]) { box(size: [0.9, 0.3, 0.3]) } }"},
      {"repeat_polar past its sector",
       "scene { repeat_polar(count: 8) { translate([0.5, 0, 0.6]) { box(size: [0.5, 0.3, 0.3]) } } }"},
      {"repeat_polar around the axis",
       "scene { repeat_polar(count: 5) { translate([0.1, 0, -0.1]) { box(size: [0.8, 0.2, 0.1]) } } }"},
      {"shell", "scene { shell(thickness: 0.1) { subtract { sphere(radius: 0.8) box(size: [2, 0.5, 2]) } } }"},
      {"transform chain",
       "scene { translate([0.2, 0.1, 0]) { rotate(axis: [0, 0, 1], degrees: 30) { scale(1.5) {\n"
       "  translate([0.1, 0, 0]) { rotate(euler: [10, 0, 45]) { box(size: [0.5, 0.3, 0.4], rounding: 0.05) } } } } } }"},
      {"bounded definitions",
       "let rod = union { rotate(axis: [0, 0, 1], degrees: 90) { capsule(radius: 0.1, height: 1) }\n"
       "  capsule(radius: 0.1, height: 1) cylinder(radius: 0.05, height: 1.5) }\n"
       "let m = diffuse(albedo: [0.5, 0.5, 0.5])\n"
       "scene { sphere(radius: 0.3, material: m) translate([1, 0, 0]) { rod } translate([-1, 0, 0]) { rod }\n"
       "  translate([0, 1, 0]) { rod } union(smooth: 0.1) { translate([0, -1, 0]) { rod } } }"},
      // Parametric definitions: specialisations (constants folded in), a
      // time-dependent argument, shape and material arguments, nested calls.
      {"parametric definitions",
       "let m = diffuse(albedo: [0.5, 0.5, 0.5])\n"
       "let post(h, r: 0.1) = union { cylinder(radius: r, height: h) translate([0, h / 2, 0]) { sphere(radius: r * 2) } }\n"
       "let pair(gap, s, k: m) = union(material: k) { translate([-gap, 0, 0]) { s } translate([gap, 0, 0]) { s } }\n"
       "scene { post(1) translate([0.5, 0, 0]) { post(0.6, r: 0.15) } translate([-0.5, 0, 0]) { post(1) }\n"
       "  translate([0, 0, 0.6]) { post(0.5 + 0.3 * sin(time)) } pair(0.7, post(0.4)) }"},
  };
}

std::vector<SceneCase> exampleScenes() {
  std::vector<SceneCase> out;
  const std::filesystem::path dir = std::filesystem::path(SDFC_SOURCE_DIR) / "examples";
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".sdf") continue;
    std::ifstream file(entry.path());
    std::stringstream text;
    text << file.rdbuf();
    out.push_back({"examples/" + entry.path().filename().string(), text.str()});
  }
  std::sort(out.begin(), out.end(), [](const SceneCase& a, const SceneCase& b) { return a.name < b.name; });
  return out;
}

struct Variant {
  const char* name;
  bool fuse;
  bool bounds;
};
// The first is the reference the others are compared with.
constexpr Variant kVariants[] = {{"unbounded", true, false},
                                 {"bounded", true, true},
                                 {"unfused", false, false}};

// The smallest "far" margin of the emitted bound checks ("if (bN > margin"):
// beyond it a bounded child may contribute its box distance instead of its
// own. Infinity when the emitter has no such checks (then bounds only skip).
double smallestBoundMargin(const std::string& glsl) {
  double smallest = INFINITY;
  const std::regex pattern(R"(if \(b[0-9]+ > ([-+0-9.eE]+))");
  for (auto it = std::sregex_iterator(glsl.begin(), glsl.end(), pattern); it != std::sregex_iterator(); ++it)
    smallest = std::min(smallest, std::stod((*it)[1].str()));
  return smallest;
}

class GpuEquivalence : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    context_ = new VulkanContext;
    createContext(*context_);
  }
  static void TearDownTestSuite() {
    destroyContext(*context_);
    delete context_;
    context_ = nullptr;
    EXPECT_EQ(validationMessageCount(), 0);
  }

  void checkScene(const SceneCase& sc) {
    SCOPED_TRACE(sc.name);
    std::vector<std::vector<float>> distances;
    std::vector<std::vector<double>> cpu_distances;
    std::vector<glm::vec3> points;
    double scale = 1, margin = INFINITY;
    dvec3 centre(0), half(3);
    for (const Variant& v : kVariants) {
      CompileOptions options;
      options.fuse_transforms = v.fuse;
      options.emit.bounding_volumes = v.bounds;
      options.emit.with_kernel = false;
      options.produce_spirv = false;
      Diagnostics diags;
      CompiledScene compiled = compileSource(sc.name, sc.text, options, diags);
      ASSERT_TRUE(compiled.ok) << diags.format();
      const std::string source = test::pointShaderSource(compiled.emitted);
      const SpirvResult spirv = glslToSpirv(source, ShaderStage::Fragment, sc.name + ".points.frag");
      ASSERT_TRUE(spirv.ok()) << spirv.log << "\n" << source;
      if (v.bounds) margin = smallestBoundMargin(compiled.emitted.glsl);

      if (points.empty()) {
        // Sample box: the scene's bounds grown by a quarter (plus a margin),
        // or a 6-unit cube around the origin for unbounded scenes. Fixed by
        // the first variant: analysis may bound fused transforms differently.
        const Aabb b = compiled.scene.root->bounds;
        if (b.finite()) {
          centre = b.center();
          half = b.halfSize() * 1.25 + 0.2;
        }
        scale = std::max({1.0, glm::length(glm::abs(centre) + half),
                          b.finite() ? std::max(glm::length(b.lo), glm::length(b.hi)) : 0.0});
      }
      const double tolerance = kBoundUlps * kUlp * scale;

      const test::GpuPoints gpu =
          test::runPoints(*context_, spirv.words, glm::vec3(centre), glm::vec3(half), 42, kTime);
      const Evaluator eval(compiled.scene, kTime);
      double worst = 0;
      int inside = 0;
      std::vector<double> cpu;
      for (size_t i = 0; i < gpu.points.size(); ++i) {
        const uint32_t x = i % test::kPointGridSide, y = i / test::kPointGridSide;
        // The shader hashed exactly the bits the CPU twin gives ...
        ASSERT_EQ(gpu.bits[i], test::pointBits(x, y, 42)) << "pixel " << x << ", " << y;
        // ... and made the point from them (up to one contraction rounding).
        const glm::dvec3 u = glm::dvec3(gpu.bits[i]) / 16777216.0;
        const glm::dvec3 expected = centre + half * (2.0 * u - 1.0);
        ASSERT_LE(glm::length(glm::dvec3(gpu.points[i]) - expected), 4 * kUlp * scale);
        const double d = eval.distance(glm::dvec3(gpu.points[i]));
        cpu.push_back(d);
        inside += d < 0;
        const double err = std::fabs(double(gpu.distances[i]) - d);
        worst = std::max(worst, err);
        // Bounded code is compared with the unbounded code below, not here.
        if (!v.bounds) {
          ASSERT_LE(err, tolerance) << v.name << " at (" << gpu.points[i].x << ", " << gpu.points[i].y
                                    << ", " << gpu.points[i].z << "): gpu " << gpu.distances[i]
                                    << ", cpu " << d;
        }
      }
      if (points.empty()) points = gpu.points;
      ASSERT_EQ(points, gpu.points);  // same seed and box, same points in every variant
      distances.push_back(gpu.distances);
      cpu_distances.push_back(cpu);
      std::printf("  %-34s %-10s S = %5.2f  max |gpu - cpu| = %.3g = %6.2f ulps of S  (%d inside)\n",
                  sc.name.c_str(), v.name, scale, worst, worst / (kUlp * scale), inside);
    }
    const double tolerance = kBoundUlps * kUlp * scale;
    int replaced = 0;
    for (size_t i = 0; i < points.size(); ++i) {
      const double unbounded = distances[0][i], bounded = distances[1][i];
      // Bounds give a lower bound, never more than the distance ...
      ASSERT_LE(bounded, unbounded + 2 * tolerance) << "point " << i;
      // ... of the same sign ...
      if (std::fabs(unbounded) > 2 * tolerance) {
        ASSERT_EQ(bounded < 0, unbounded < 0) << "point " << i;
      }
      // ... and the distance itself wherever it is below every margin.
      if (bounded < margin) {
        ASSERT_NEAR(bounded, unbounded, 2 * tolerance) << "point " << i;
      }
      replaced += std::fabs(bounded - unbounded) > 2 * tolerance;
      // Fusion changes float32 rounding only, and the float64 field not at all.
      ASSERT_NEAR(distances[0][i], distances[2][i], 2 * tolerance) << "point " << i;
      ASSERT_NEAR(cpu_distances[0][i], cpu_distances[2][i], 1e-9 * scale) << "point " << i;
    }
    std::printf("  %-34s bounded: %d of %zu points got a box distance (margin %g)\n", sc.name.c_str(),
                replaced, points.size(), margin);
  }

  static VulkanContext* context_;
};

VulkanContext* GpuEquivalence::context_ = nullptr;

TEST_F(GpuEquivalence, HashTwinIsBitExact) {
  // A fixed value, so a change on either side shows up here first.
  const glm::uvec3 b = test::pointBits(0, 0, 0);
  EXPECT_EQ(b, test::pointBits(0, 0, 0));
  EXPECT_NE(test::pointBits(1, 0, 0), b);
  EXPECT_LT(b.x, 1u << 24);
}

TEST_F(GpuEquivalence, EveryPrimitive) {
  for (const SceneCase& sc : primitiveScenes()) checkScene(sc);
}

TEST_F(GpuEquivalence, EveryOperator) {
  for (const SceneCase& sc : operatorScenes()) checkScene(sc);
}

TEST_F(GpuEquivalence, EveryExample) {
  const std::vector<SceneCase> examples = exampleScenes();
  ASSERT_FALSE(examples.empty());
  for (const SceneCase& sc : examples) checkScene(sc);
}

}  // namespace
}  // namespace sdfc
