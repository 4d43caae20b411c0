// The block evaluator (eval/block_evaluator.h) against the per-point one:
// distance, material and gradient equal bit for bit on every example and on
// a scene holding every node kind (checked to be there), at random points, on
// the surface, on cell borders, at signed zeros, partial blocks included.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <random>
#include <set>

#include "driver/compile.h"
#include "eval/block_evaluator.h"
#include "passes/passes.h"

namespace sdfc {
namespace {

using glm::dvec3;

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

void collectKinds(const ir::Node& n, std::set<ir::NodeKind>& kinds) {
  kinds.insert(n.kind);
  for (const ir::NodeRef& c : n.children) collectKinds(*c, kinds);
}

std::vector<double> testPoints(const ir::Scene& scene, double time) {
  Aabb box = scene.root ? scene.root->bounds : Aabb::infinite();
  if (!box.finite()) box = {dvec3(-8), dvec3(8)};
  box = box.grow(0.5 + 0.1 * glm::length(box.hi - box.lo));
  box = box.intersect({dvec3(-1e3), dvec3(1e3)});
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> u(0, 1);
  const Evaluator eval(scene, time);
  std::vector<double> xyz;
  auto add = [&](dvec3 p) { xyz.insert(xyz.end(), {p.x, p.y, p.z}); };
  for (int i = 0; i < 700; ++i) {
    const dvec3 p = box.lo + (box.hi - box.lo) * dvec3(u(rng), u(rng), u(rng));
    add(p);
    // A step onto the surface, where materials change and blends act.
    const dvec3 g = eval.gradient(p);
    const double d = eval.distance(p);
    if (std::isfinite(d) && glm::length(g) > 0) add(p - d * g / glm::dot(g, g));
    // Grid-like points: halves and quarters, cell borders of repeats.
    add(glm::round(p * 4.0) / 4.0);
  }
  for (double x : {0.0, -0.0, 0.45, -0.45, 0.5, -0.5, 1.0})
    for (double z : {0.0, -0.0, 0.9}) add(dvec3(x, -0.0, z));
  add(dvec3(1e30, -1e30, 1e30));
  return xyz;  // 2127 points: 16 full blocks and a partial one
}

void expectSame(const CompiledScene& c, const std::string& name, double time, bool prune = false) {
  const ir::Scene& scene = c.scene;
  const std::vector<double> xyz = testPoints(scene, time);
  const size_t n = xyz.size() / 3;
  const Evaluator point(scene, time);
  const BlockEvaluator block(scene, time, prune);
  BlockEvaluator::Scratch scratch;
  std::vector<double> distance(n), gradient(3 * n);
  std::vector<int> material(n);
  block.evaluate(xyz.data(), n, distance.data(), material.data(), scratch);
  block.gradient(xyz.data(), n, gradient.data(), scratch);
  int mismatches = 0;
  for (size_t i = 0; i < n && mismatches < 5; ++i) {
    const dvec3 p(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    const EvalResult r = point.at(p);
    const dvec3 g = point.gradient(p);
    const bool same = sameBits(r.distance, distance[i]) && r.material == material[i] &&
                      sameBits(g.x, gradient[3 * i]) && sameBits(g.y, gradient[3 * i + 1]) &&
                      sameBits(g.z, gradient[3 * i + 2]);
    if (!same) {
      ++mismatches;
      ADD_FAILURE() << name << " at (" << p.x << ", " << p.y << ", " << p.z << "): point " << r.distance << " m"
                    << r.material << ", block " << distance[i] << " m" << material[i] << (prune ? " (pruned)" : "");
    }
  }
}

// Every .sdf of the folders (under the source tree), compiled, to `check`.
void forEachScene(std::initializer_list<const char*> folders,
                  const std::function<void(const CompiledScene&, const std::string&)>& check) {
  for (const char* folder : folders) {
    for (const auto& entry : std::filesystem::directory_iterator(std::string(SDFC_SOURCE_DIR) + folder)) {
      if (entry.path().extension() != ".sdf") continue;
      Diagnostics diags;
      CompileOptions options;
      options.produce_spirv = false;
      const CompiledScene c = compileFile(entry.path().string(), options, diags);
      ASSERT_TRUE(c.ok) << entry.path() << "\n" << diags.format();
      check(c, entry.path().filename().string());
    }
  }
}

TEST(BlockEvaluator, EqualsPerPointOnEveryExample) {
  int scenes = 0;
  forEachScene({"/examples", "/examples/hard"}, [&](const CompiledScene& c, const std::string& name) {
    for (double time : {0.0, 0.37}) expectSame(c, name, time);
    ++scenes;
  });
  EXPECT_GE(scenes, 30);
}

// With the root union's prune grid (mesh, large eval batches): the same bits
// on every example and bench scene, at two times (moving parts are never pruned).
TEST(BlockEvaluator, PrunedEqualsPerPoint) {
  int pruned = 0;
  forEachScene({"/examples", "/examples/hard", "/bench/scenes"}, [&](const CompiledScene& c, const std::string& name) {
    pruned += buildPruneGrid(c.scene) != nullptr;
    for (double time : {0.0, 0.37}) expectSame(c, name, time, true);
  });
  EXPECT_GE(pruned, 10);  // scenes with a grid, where the pruned path ran
}

// Every node kind, with materials, colour fields, time, smooth blends,
// parametric calls and a mesh, each in a form the passes keep.
const char* kEveryKind = R"(
let red = diffuse(albedo: [0.8, 0.1, 0.1])
let blue = metal(albedo: noise([0.1, 0.1, 0.8], [0.9, 0.9, 0.9], scale: 3))
let checks = diffuse(albedo: checker([0.2, 0.2, 0.2], [0.9, 0.9, 0.9], size: 0.5))
let post(h: 1) = union(smooth: 0.1) { cylinder(radius: 0.2, height: h) translate([0, h / 2, 0]) { sphere(radius: 0.3) } }
scene {
  plane(offset: -3, material: checks)
  union(smooth: 0.2, material: red) {
    sphere(radius: 1)
    translate([1, 0.3, 0]) { box(size: [1, 2, 1], rounding: 0.1, material: blue) }
    torus(major: 1, minor: 0.2)
  }
  translate([3, 0, 0]) {
    intersect(smooth: 0.1) { cone(radius: 1, height: 2) capsule(radius: 0.5, height: 1, material: blue) }
    subtract(smooth: 0.05) { prism(size: 1, depth: 1) hexprism(radius: 0.3, depth: 2) }
  }
  translate([0, 3, 0]) { rotate(axis: [1, 1, 0], degrees: 30 + 10 * sin(time)) { scale(factor: 1.5) { octahedron(radius: 0.5) } } }
  translate([0, -3, 0]) { scale(factor: [1, 2, 0.5]) { pyramid(size: 1, height: 1) } }
  translate([-3, 0, 0]) { reflect(normal: [1, 0, 0], offset: 0.2) { translate([0.5, 0, 0]) { round_cone(bottom: 0.3, top: 0.1, height: 1) } } }
  translate([0, 0, 3]) { repeat(cell: [1, 0, 1], count: [3, 0, 0]) { translate([0.3, 0, 0]) { ellipsoid(radii: [0.6, 0.3, 0.2], material: blue) } } }
  translate([0, 0, -3]) { elongate(amount: [0.5, 0, 0.2]) { menger(level: 2, size: 1) } }
  translate([3, 3, 0]) { morph(t: 0.5 + 0.5 * sin(3 * time)) { box(size: [1, 1, 1], material: blue) sphere(radius: 0.6) } }
  translate([-3, 3, 0]) { round(radius: 0.1) { box(size: [0.5, 0.5, 0.5]) } shell(thickness: 0.05) { sphere(radius: 0.7) } }
  translate([3, -3, 0]) { extrude(depth: 0.3) { subtract { rect(size: [1.2, 1.2], rounding: 0.25) circle(radius: 0.3) } } }
  translate([-3, -3, 0]) { revolve(offset: 0.5) { hexagon(radius: 0.2) } revolve { polygon(points: [[0, 0], [0.5, 0], [0.3, 1], [0, 1]]) } }
  translate([3, 0, 3]) { twist(rate: 90 + 20 * sin(time), material: red) { box(size: [0.7, 2, 0.7]) } }
  translate([-3, 0, -3]) { instances(positions: [[0, 0, 0], [0.9, 0, 0], [0, 0.8, 0.3, 0.5]], smooth: 0.3) { sphere(radius: 0.5) } }
  translate([3, 0, -3]) { post(h: 2) post() }
  translate([-3, 0, 3]) { scale(factor: 0.5) { mesh(file: "../examples/meshes/tetrahedron.obj", material: blue) } }
}
)";

TEST(BlockEvaluator, EqualsPerPointForEveryNodeKind) {
  Diagnostics diags;
  CompileOptions options;
  options.produce_spirv = false;
  options.instancing.threshold = 2;  // the three instances stay an Instances node
  const std::string path = std::string(SDFC_SOURCE_DIR) + "/tests/every_kind.sdf";
  for (bool fuse : {true, false}) {
    options.fuse_transforms = fuse;
    const CompiledScene c = compileSource(path, kEveryKind, options, diags);
    ASSERT_TRUE(c.ok) << diags.format();
    std::set<ir::NodeKind> kinds;
    collectKinds(*c.scene.root, kinds);
    // Affine only when transforms are fused; the plain ones when not.
    for (ir::NodeKind k : {ir::NodeKind::Primitive, ir::NodeKind::Union, ir::NodeKind::Intersect,
                           ir::NodeKind::Subtract, ir::NodeKind::Reflect, ir::NodeKind::Repeat,
                           ir::NodeKind::Elongate, ir::NodeKind::Morph, ir::NodeKind::Round,
                           ir::NodeKind::Shell, ir::NodeKind::Extrude, ir::NodeKind::Revolve,
                           ir::NodeKind::Twist, ir::NodeKind::Instances, ir::NodeKind::Mesh})
      EXPECT_TRUE(kinds.count(k)) << "kind " << int(k) << " missing, fuse " << fuse;
    if (fuse) {
      EXPECT_TRUE(kinds.count(ir::NodeKind::Affine));
    } else {
      for (ir::NodeKind k : {ir::NodeKind::Translate, ir::NodeKind::Rotate, ir::NodeKind::Scale,
                             ir::NodeKind::ScaleNonUniform})
        EXPECT_TRUE(kinds.count(k)) << "kind " << int(k) << " missing";
    }
    for (double time : {0.0, 0.8, 2.1}) expectSame(c, fuse ? "every kind, fused" : "every kind", time);
  }
}

}  // namespace
}  // namespace sdfc
