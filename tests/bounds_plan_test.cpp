// The bounding-volume plan for CPU devices (passes/bounds_plan.cpp): checks
// are kept where lockstep groups of rays skip the child, dropped where the
// boxes overlap the whole view, decided the same way every time within the
// sampling budget, and they never change what the kernel draws.
#include <gtest/gtest.h>

#include <string>

#include "driver/compile.h"
#include "scene_render.h"
#include "vulkan_context.h"

namespace sdfc {
namespace {

CompileOptions cpuOptions() {
  CompileOptions o;
  o.emit.bounding_volumes = false;
  o.emit.planned_bounds = true;
  o.emit.march.image_height = 90;
  return o;
}

CompiledScene compileText(const std::string& text, const CompileOptions& options) {
  Diagnostics diags;
  CompiledScene c = compileSource("plan.sdf", text, options, diags);
  EXPECT_TRUE(c.ok) << diags.format();
  return c;
}

size_t count(const std::string& haystack, const std::string& needle) {
  size_t n = 0;
  for (size_t at = haystack.find(needle); at != std::string::npos; at = haystack.find(needle, at + 1)) ++n;
  return n;
}

// Three clusters of four distinct parts, far apart next to their size: most
// groups of rays are near one cluster at a time, and a cluster (about 40
// primitives' worth) is worth a check where a single part is not.
std::string separatedParts() {
  std::string s = "render(size: [160, 90])\ncamera(position: [0, 3, 6], target: [0, 0.3, 0], fov: 100)\n"
                  "sun(direction: [0.3, 1, 0.2])\nscene {\n";
  for (int c = 0; c < 3; ++c) {
    s += "  translate([" + std::to_string(-8 + 8 * c) + ", 0.5, 0]) { union {\n";
    for (int i = 0; i < 4; ++i) {
      const double x = (i % 2) * 1.2 - 0.6, z = (i / 2) * 1.2 - 0.6, r = 0.3 + 0.02 * (4 * c + i);
      const std::string R = std::to_string(r);
      s += "    translate([" + std::to_string(x) + ", 0, " + std::to_string(z) + "]) { union { subtract { sphere(radius: " +
           std::to_string(r + 0.1) + ") box(size: [" + R + ", 2, " + R + "]) } torus(major: " + R +
           ", minor: 0.05) translate([0, 0.5, 0]) { capsule(radius: 0.05, height: 0.6) } "
           "revolve { polygon(points: [[0, -0.4], [0.2, -0.4], [0.12, -0.2], [0.18, 0], [0.1, 0.2], [0.14, 0.3], [0, 0.35]]) } } }\n";
    }
    s += "  } }\n";
  }
  return s + "}\n";
}

// Four costly children whose boxes are all the same cube, filling the view:
// a group is never farther from a child's box than from the union so far.
const char* kOverlapping = R"(
render(size: [160, 90])
camera(position: [0, 1, 7], target: [0, 0, 0], fov: 50)
scene {
  intersect { box(size: [5, 5, 5]) sphere(radius: 2.8) rotate(axis: [0, 1, 0], degrees: 10) { box(size: [4.6, 6, 4.6]) } }
  intersect { box(size: [5, 5, 5]) sphere(radius: 2.85) rotate(axis: [0, 1, 0], degrees: 20) { box(size: [4.6, 6, 4.6]) } }
  intersect { box(size: [5, 5, 5]) sphere(radius: 2.9) rotate(axis: [0, 1, 0], degrees: 30) { box(size: [4.6, 6, 4.6]) } }
  intersect { box(size: [5, 5, 5]) sphere(radius: 2.95) rotate(axis: [0, 1, 0], degrees: 40) { box(size: [4.6, 6, 4.6]) } }
}
)";

TEST(BoundsPlan, KeepsChecksWhereGroupsSkipTheChild) {
  const CompiledScene c = compileText(separatedParts(), cpuOptions());
  EXPECT_GT(c.bounds_plan.tiles, 16);
  EXPECT_GE(c.bounds_plan.checks, 3) << ir::dump(c.scene);
  EXPECT_EQ(c.emitted.stats.bounded_subtrees, c.bounds_plan.checks);
  EXPECT_EQ(count(c.emitted.glsl, "sdBound(p"), size_t(c.bounds_plan.checks));
  const std::string ir = ir::dump(c.scene);
  EXPECT_EQ(count(ir, ", box check (skips"), size_t(c.bounds_plan.checks)) << ir;
}

TEST(BoundsPlan, DropsChecksWhereBoxesOverlapTheView) {
  const CompiledScene c = compileText(kOverlapping, cpuOptions());
  EXPECT_GE(c.bounds_plan.candidates, 3) << ir::dump(c.scene);
  EXPECT_EQ(c.bounds_plan.checks, 0) << ir::dump(c.scene);
  EXPECT_EQ(c.emitted.glsl.find("sdBound("), std::string::npos);
  // A GPU (or --bounds) still gets every check; --no-bounds none.
  CompileOptions all = cpuOptions();
  all.emit.bounding_volumes = true;
  EXPECT_GE(compileText(kOverlapping, all).emitted.stats.bounded_subtrees, 3);
  CompileOptions none = cpuOptions();
  none.emit.planned_bounds = false;
  const CompiledScene n = compileText(separatedParts(), none);
  EXPECT_EQ(n.emitted.stats.bounded_subtrees, 0);
  EXPECT_EQ(n.bounds_plan.tiles, 0);
}

TEST(BoundsPlan, SameDecisionsEveryTimeAndWithinItsBudget) {
  const std::string text = separatedParts();
  const CompiledScene a = compileText(text, cpuOptions()), b = compileText(text, cpuOptions());
  EXPECT_EQ(a.emitted.glsl, b.emitted.glsl);
  EXPECT_EQ(ir::dump(a.scene), ir::dump(b.scene));
  // A small budget stops the sampling early, with the decisions it can make.
  CompileOptions tight = cpuOptions();
  Diagnostics diags;
  CompiledScene small = compileSource("plan.sdf", text, tight, diags);
  ASSERT_TRUE(small.ok);
  const double budget = a.bounds_plan.work / 4;
  const BoundsPlan p = planBoundChecks(small.scene, tight.emit.march, tight.emit.bound_cost_threshold, budget);
  EXPECT_LT(p.tiles, a.bounds_plan.tiles);
  // One group step past the budget at most: the whole scene's work for 8 lanes.
  EXPECT_LE(p.work, budget + 8 * small.scene.root->cost + 64);
  EXPECT_GT(p.work, budget);
}

// The kernel with the planned checks draws what the one without draws: the
// same depth wherever the march is not grazing a silhouette.
TEST(BoundsPlan, PlannedChecksDrawTheSameDepth) {
  const std::string text = separatedParts();
  CompileOptions none = cpuOptions();
  none.emit.planned_bounds = false;
  const CompiledScene planned = compileText(text, cpuOptions()), plain = compileText(text, none);
  ASSERT_GE(planned.emitted.stats.bounded_subtrees, 3);
  VulkanContext context;
  createContext(context);
  auto depth = [&](const CompiledScene& c) {
    Renderer r(context, c);
    RenderOverrides o;
    o.width = 160;
    o.height = 90;
    o.spp = 1;
    o.view = gpu::kViewDepth;
    return r.render(cameraFor(c.scene), renderSettingsFor(c, o)).color;
  };
  const FloatImage a = depth(planned), b = depth(plain);
  destroyContext(context);
  ASSERT_EQ(a.rgba.size(), b.rgba.size());
  int hits = 0, differ = 0;
  for (size_t i = 0; i < a.rgba.size(); i += 4) {
    const float da = a.rgba[i], db = b.rgba[i];
    hits += db > 0 && db < 1e6f;
    // A check may replace a far child by its box distance: a shorter step, so
    // the march may stop at another point within the hit band.
    if (std::abs(da - db) > 2e-3f * std::max(1.0f, std::abs(db))) ++differ;
  }
  EXPECT_GT(hits, 300);
  // A grazing ray may pass a silhouette by another sequence of steps: at most
  // 1% of the hits (2 of 408 here).
  EXPECT_LE(differ, hits / 100) << differ << " of " << hits << " hit pixels at another depth";
  EXPECT_EQ(validationMessageCount(), 0);
}

// Nested hard unions take what the unions above them have so far (their
// "cut"): a box beyond it is skipped. Rows of distinct pieces (definitions,
// each a union, under translations, rotations and a reflection), each piece
// its own material: with every check (and so every cut) the kernel draws the
// depth and the albedo that the one without checks draws.
TEST(BoundsPlan, CutsFromEnclosingUnionsChangeNoDepthNorMaterial) {
  std::string s = "render(size: [160, 90])\ncamera(position: [0, 4, 7], target: [0, 0.5, 0], fov: 60)\n"
                  "sun(direction: [0.3, 1, 0.2])\n";
  const char* colours[] = {"[0.9, 0.2, 0.2]", "[0.2, 0.9, 0.2]", "[0.2, 0.2, 0.9]", "[0.9, 0.9, 0.2]"};
  for (int m = 0; m < 4; ++m) s += "let m" + std::to_string(m) + " = diffuse(albedo: " + colours[m] + ")\n";
  s += "let piece(r, m) = union(material: m) { cylinder(radius: r, height: 0.3) "
       "translate([0, 0.5, 0]) { sphere(radius: r * 0.8) } "
       "revolve { polygon(points: [[0, 0.1], [0.2, 0.1], [0.1, 0.6], [0, 0.6]]) } }\n"
       "let row(m, n) = union { translate([-1.5, 0, 0]) { piece(0.3, m) } translate([-0.5, 0, 0]) { piece(0.25, n) } "
       "rotate(axis: [0, 1, 0], degrees: 30) { translate([0.5, 0, 0]) { piece(0.2, m) } } "
       "translate([1.5, 0, 0]) { piece(0.35, n) } }\n"
       "scene {\n  box(size: [6, 0.1, 6], material: m3)\n"
       "  translate([0, 0, -1.5]) { row(m0, m1) }\n  translate([0, 0, 0]) { row(m1, m2) }\n"
       "  reflect(normal: [0, 0, 1]) { translate([0, 0, 1.5]) { row(m2, m0) } }\n}\n";
  CompileOptions all = cpuOptions();
  all.emit.bounding_volumes = true;
  CompileOptions none = cpuOptions();
  none.emit.planned_bounds = false;
  const CompiledScene checked = compileText(s, all), plain = compileText(s, none);
  // The cut reaches the pieces' functions through the rows'.
  EXPECT_NE(checked.emitted.glsl.find("float sd_row(vec3 p, float cut)"), std::string::npos) << checked.emitted.glsl;
  EXPECT_NE(checked.emitted.glsl.find(" < min(d0, cut))) {"), std::string::npos);
  EXPECT_EQ(plain.emitted.glsl.find("float cut"), std::string::npos);
  VulkanContext context;
  createContext(context);
  auto view = [&](const CompiledScene& c, uint32_t v) {
    Renderer r(context, c);
    RenderOverrides o;
    o.width = 160;
    o.height = 90;
    o.spp = 1;
    o.view = v;
    return r.render(cameraFor(c.scene), renderSettingsFor(c, o)).color;
  };
  const FloatImage da = view(checked, gpu::kViewDepth), db = view(plain, gpu::kViewDepth);
  const FloatImage aa = view(checked, gpu::kViewAlbedo), ab = view(plain, gpu::kViewAlbedo);
  destroyContext(context);
  ASSERT_EQ(da.rgba.size(), db.rgba.size());
  int hits = 0, depth_differ = 0, albedo_differ = 0;
  for (size_t i = 0; i < da.rgba.size(); i += 4) {
    const float a = da.rgba[i], b = db.rgba[i];
    if (!(b > 0 && b < 1e6f)) continue;
    ++hits;
    if (std::abs(a - b) > 2e-3f * std::max(1.0f, std::abs(b))) ++depth_differ;
    for (int c = 0; c < 3; ++c)
      if (std::abs(aa.rgba[i + c] - ab.rgba[i + c]) > 1e-4f) {
        ++albedo_differ;
        break;
      }
  }
  EXPECT_GT(hits, 2000);
  // Grazing rays may pass a silhouette by another sequence of steps.
  EXPECT_LE(depth_differ, hits / 100) << depth_differ << " of " << hits;
  EXPECT_LE(albedo_differ, hits / 100) << albedo_differ << " of " << hits;
  EXPECT_EQ(validationMessageCount(), 0);
}

}  // namespace
}  // namespace sdfc
