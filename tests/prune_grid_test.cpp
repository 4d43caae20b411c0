// The root union's prune grid (passes/prune_grid.cpp, `--prune`): in every
// cell the listed parts give the union's value exactly. Checked in float64
// against the whole union at random points of generated scenes (nested unions
// with materials, definitions, rotated parts, planes, parts that move) and of
// the examples, and through the kernel: the same pixels with and without it.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "camera.h"
#include "driver/compile.h"
#include "eval/evaluator.h"
#include "passes/passes.h"
#include "scene_render.h"
#include "vulkan_context.h"

namespace sdfc {
namespace {

using glm::dvec3;

std::string readFile(const std::string& relative) {
  std::ifstream in(std::string(SDFC_SOURCE_DIR) + "/" + relative);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Rows of rotated parts of five kinds in nested unions, some with their own
// material, beside a ground plane; `moving` parts follow time.
std::string nestedParts(unsigned seed, int rows, int per_row, bool moving) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1), size(0.15, 0.45), angle(0, 180);
  std::ostringstream s;
  s << "camera(position: [6, 5, 9], target: [0, 0.5, 0], fov: 45)\nsun(direction: [0.5, 1, 0.3])\n"
       "let red = diffuse(albedo: [0.8, 0.1, 0.1])\nlet blue = diffuse(albedo: [0.1, 0.1, 0.8])\n"
       "let post(h) = union { cylinder(radius: 0.1, height: h) translate([0, h / 2, 0]) { sphere(radius: 0.15) } }\n"
       "scene {\n  plane(normal: [0, 1, 0], offset: -0.5)\n";
  const char* kinds[] = {"sphere(radius: %g)", "box(size: [%g, 0.3, 0.25])", "capsule(radius: 0.1, height: %g)",
                         "torus(major: %g, minor: 0.07)", "post(%g)"};
  for (int r = 0; r < rows; ++r) {
    s << "  union" << (r % 3 == 0 ? "(material: red)" : r % 3 == 1 ? "(material: blue)" : "") << " {\n";
    for (int i = 0; i < per_row; ++i) {
      const dvec3 p((i - per_row / 2.0) * 0.9 + 0.2 * u(rng), 0.3 * u(rng), (r - rows / 2.0) * 1.1 + 0.2 * u(rng));
      char part[80];
      std::snprintf(part, sizeof part, kinds[(r + i) % 5], size(rng) * (((r + i) % 5) == 4 ? 3 : 1));
      s << "    translate([" << p.x << (moving && i == 0 ? " + 0.3 * sin(time)" : "") << ", " << p.y << ", " << p.z
        << "]) { rotate(axis: [" << u(rng) << ", 1, " << u(rng) << "], degrees: " << angle(rng) << ") { " << part
        << " } }\n";
    }
    s << "  }\n";
  }
  s << "}\n";
  return s.str();
}

CompiledScene compiledWithPrune(const std::string& name, const std::string& text, bool prune, bool spirv = false) {
  CompileOptions options;
  options.produce_spirv = spirv;
  options.emit.prune = prune;
  options.emit.bounding_volumes = false;  // bounds' far exits would change the values
  options.emit.planned_bounds = false;
  Diagnostics diags;
  CompiledScene c = compileSource(name, text, options, diags);
  EXPECT_TRUE(c.ok) << diags.format();
  return c;
}

// The union over the parts the cell of p lists (every part outside the grid),
// in float64; -2 material when nothing is listed.
EvalResult prunedUnion(const Evaluator& eval, const ir::PruneGrid& g, const dvec3& p, int root_material) {
  const std::array<std::uint32_t, 4> mask = pruneMaskAt(g, p);
  EvalResult best{1e30, -2};
  for (size_t i = 0; i < g.parts.size(); ++i) {
    if (!g.lists(mask, i)) continue;
    const EvalResult r = eval.evalNode(*g.parts[i], p, g.inherited[i] >= 0 ? g.inherited[i] : root_material);
    if (r.distance < best.distance) best = r;
  }
  return best;
}

// At random points in and around the grid: the listed parts' union is the
// whole union, value and material, bit for bit; and most cells list few parts.
void expectExactEverywhere(const std::string& what, const std::string& text, double max_kept) {
  const CompiledScene c = compiledWithPrune(what, text, true);
  ASSERT_TRUE(c.scene.root && c.scene.root->prune) << what << ": no grid";
  const ir::PruneGrid& g = *c.scene.root->prune;
  const Evaluator eval(c.scene);
  std::mt19937 rng(7);
  const dvec3 size = dvec3(g.dims) * g.cell;
  std::uniform_real_distribution<double> u(-0.1, 1.1);
  int checked = 0, differ = 0;
  for (int k = 0; k < 20000; ++k) {
    const dvec3 p = g.lo + dvec3(u(rng), u(rng), u(rng)) * size;
    const EvalResult whole = eval.at(p);
    const EvalResult pruned = prunedUnion(eval, g, p, c.scene.root->material);
    ++checked;
    if (whole.distance != pruned.distance || whole.material != pruned.material) {
      if (differ < 3)
        ADD_FAILURE() << what << " at " << p.x << ", " << p.y << ", " << p.z << ": whole " << whole.distance << " (material "
                      << whole.material << "), pruned " << pruned.distance << " (" << pruned.material << ")";
      ++differ;
    }
  }
  const size_t pruned_parts = g.prunedParts();
  std::printf("[ prune    ] %s: %zu of %zu parts pruned on %dx%dx%d cells, a cell keeps %.0f%% of their cost; "
              "%d of %d points differ\n",
              what.c_str(), pruned_parts, g.parts.size(), g.dims.x, g.dims.y, g.dims.z, 100 * g.kept_cost, differ,
              checked);
  EXPECT_EQ(differ, 0) << what;
  EXPECT_LE(g.kept_cost, max_kept) << what;
}

TEST(PruneGrid, ListedPartsGiveTheWholeUnion) {
  expectExactEverywhere("4 rows of 8 nested parts", nestedParts(1, 4, 8, false), 0.3);
  expectExactEverywhere("8 rows of 10 nested parts", nestedParts(2, 8, 10, false), 0.2);
  expectExactEverywhere("castle", readFile("examples/castle.sdf"), 0.5);
  expectExactEverywhere("chess set", readFile("bench/scenes/chess_set.sdf"), 0.1);
  expectExactEverywhere("mixed materials", readFile("examples/mixed_materials.sdf"), 1);
}

// Parts that move, planes and top-level spheres (which the kernel may take
// out of the union) are never pruned, and no pruning relies on them.
TEST(PruneGrid, MovingPartsPlanesAndSpheresAreAlwaysEvaluated) {
  const CompiledScene c = compiledWithPrune("moving.sdf", nestedParts(3, 4, 6, true), true);
  ASSERT_TRUE(c.scene.root->prune);
  const ir::PruneGrid& g = *c.scene.root->prune;
  int moving = 0, planes = 0;
  for (size_t i = 0; i < g.parts.size(); ++i) {
    const ir::Node& n = *g.parts[i];
    if (n.kind == ir::NodeKind::Primitive && n.primitive == PrimitiveKind::Plane) {
      ++planes;
      EXPECT_EQ(g.bit[i], -1);
    }
    if (n.kind == ir::NodeKind::Translate && !n.vec.isConst()) {
      ++moving;
      EXPECT_EQ(g.bit[i], -1);
    }
  }
  EXPECT_EQ(planes, 1);
  EXPECT_EQ(moving, 4);
  const CompiledScene s = compiledWithPrune(
      "spheres.sdf", "scene { sphere(radius: 1) translate([3, 0, 0]) { sphere(radius: 1) } box(size: [1, 1, 1]) "
                     "translate([0, 3, 0]) { box(size: [1, 1, 1]) } }\n",
      true);
  ASSERT_TRUE(s.scene.root->prune);
  for (size_t i = 0; i < s.scene.root->prune->parts.size(); ++i)
    if (s.scene.root->prune->parts[i]->kind != ir::NodeKind::Primitive ||
        s.scene.root->prune->parts[i]->primitive == PrimitiveKind::Sphere)
      EXPECT_TRUE(s.scene.root->prune->parts[i]->kind != ir::NodeKind::Primitive || s.scene.root->prune->bit[i] == -1);
}

// Through the kernel: depth, normal, albedo and beauty the same bits with and
// without the grid (bounding volumes off in both: their far exits differ).
TEST(PruneGridGpu, KernelDrawsTheSamePixels) {
  VulkanContext context;
  createContext(context);
  for (const auto& [what, text] : std::vector<std::pair<std::string, std::string>>{
           {"nested parts", nestedParts(4, 5, 8, false)},
           {"castle", readFile("examples/castle.sdf")},
           {"chess set", readFile("bench/scenes/chess_set.sdf")}}) {
    std::vector<float> images[2];
    for (int prune = 0; prune < 2; ++prune) {
      const CompiledScene c = compiledWithPrune(what, text, prune, true);
      ASSERT_TRUE(c.ok);
      EXPECT_EQ(c.emitted.glsl.find("sdPruneMask") != std::string::npos, prune == 1) << what;
      RenderOverrides o;
      o.width = 96;
      o.height = 54;
      o.spp = 2;
      Renderer r(context, c);
      const RenderOutput out = r.render(cameraFor(c.scene), renderSettingsFor(c, o));
      for (const FloatImage* im : {&out.color, &out.normal_depth, &out.albedo_steps})
        images[prune].insert(images[prune].end(), im->rgba.begin(), im->rgba.end());
    }
    ASSERT_EQ(images[0].size(), images[1].size());
    size_t differ = 0;
    for (size_t i = 0; i < images[0].size(); ++i) differ += images[0][i] != images[1][i];
    EXPECT_EQ(differ, 0u) << what;
  }
  destroyContext(context);
  EXPECT_EQ(validationMessageCount(), 0);
}

}  // namespace
}  // namespace sdfc
