// Large scenes as data (docs/design/large_scenes.md): a union's copies of one shape
// become an Instances node with a hierarchy. The float64 evaluator through
// the hierarchy must equal the inline union (brute force) exactly; the GPU
// form must match the evaluator within float32 and the inline images beyond
// noise; `instances(...)` is checked like everything else.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <unistd.h>

#include "camera.h"
#include "driver/compile.h"
#include "eval/evaluator.h"
#include "gpu_points.h"
#include "passes/passes.h"
#include "scene_render.h"
#include "vulkan_context.h"

namespace sdfc {
namespace {

using glm::dvec3;

// 300 children: boxes of two sizes (rotated and scaled copies among them),
// spheres of varied radius, in three materials, plus a plane.
std::string mixedScene(int count = 300) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-6, 6), r(0.1, 0.6), a(0, 360);
  std::ostringstream s;
  s << "let red = diffuse(albedo: [0.8, 0.1, 0.1])\nlet blue = diffuse(albedo: [0.1, 0.1, 0.8])\n"
       "let grey = diffuse(albedo: [0.5, 0.5, 0.5])\nscene {\n  plane(offset: -7)\n";
  for (int i = 0; i < count; ++i) {
    const double x = u(rng), y = u(rng), z = u(rng);
    const char* m = i % 3 == 0 ? "red" : i % 3 == 1 ? "blue" : "grey";
    s << "  translate([" << x << ", " << y << ", " << z << "]) { ";
    if (i % 2 == 0) {
      s << "rotate(axis: [0, 1, 0.3], degrees: " << a(rng) << ") { scale(" << 0.5 + r(rng) << ") { box(size: ["
        << (i % 4 == 0 ? "0.5, 0.3, 0.4" : "0.2, 0.6, 0.2") << "], material: " << m << ") } }";
    } else {
      s << "sphere(radius: " << r(rng) << ", material: " << m << ")";
    }
    s << " }\n";
  }
  s << "}\n";
  return s.str();
}

CompiledScene checked(const std::string& text, int threshold) {
  CompileOptions options;
  options.instancing.threshold = threshold;
  Diagnostics diags;
  CompiledScene c = checkSource("test.sdf", text, options, diags);
  EXPECT_TRUE(c.ok) << diags.format();
  return c;
}

int countKind(const ir::Node& n, ir::NodeKind kind) {
  int count = n.kind == kind;
  for (const ir::NodeRef& c : n.children) count += countKind(*c, kind);
  return count;
}

TEST(Instances, UnionOfCopiesBecomesDataAndDumpSaysSo) {
  const CompiledScene data = checked(mixedScene(), 32);
  const CompiledScene inline_form = checked(mixedScene(), 0);
  // Boxes (two sizes: per-instance parameters; rotated and scaled) and
  // spheres: one mixed set of two templates (issue 46: one search, not two).
  EXPECT_EQ(countKind(*data.scene.root, ir::NodeKind::Instances), 1);
  EXPECT_EQ(countKind(*inline_form.scene.root, ir::NodeKind::Instances), 0);
  const std::string dump = ir::dump(data.scene);
  EXPECT_NE(dump.find("instances 300 (data form: union of 300 "), std::string::npos) << dump;
  EXPECT_NE(dump.find("per-instance params 4"), std::string::npos);  // box sizes and sphere radii differ
  // Below the threshold the union stays code.
  EXPECT_EQ(countKind(*checked(mixedScene(20), 32).scene.root, ir::NodeKind::Instances), 0);
}

TEST(Instances, NestedSetsStayWithinTheCountedTraversals) {
  // A set inside a set's template would run a loop per outer visit: the outer
  // copies stay code, and each counts as one traversal of the inner set.
  std::ostringstream s;
  s << "scene { instances(positions: [";
  for (int i = 0; i < 40; ++i) s << (i ? ", " : "") << "[" << i * 3 << ", 0, 0]";
  s << "]) { instances(positions: [";
  for (int i = 0; i < 40; ++i) s << (i ? ", " : "") << "[0, " << i * 0.5 << ", 0]";
  s << "]) { sphere(radius: 0.2) } } }";
  CompileOptions options;
  options.produce_spirv = false;
  Diagnostics diags;
  const CompiledScene c = compileSource("nested.sdf", s.str(), options, diags);
  ASSERT_TRUE(c.ok) << diags.format();
  EXPECT_EQ(c.emitted.stats.instance_sets, 1);
  EXPECT_EQ(c.emitted.stats.traversals_per_evaluation, 40);
  EXPECT_NEAR(Evaluator(c.scene).distance(dvec3(3, 1, 0)), -0.2, 1e-12);
}

// 400 spheres of varied radii, overlapping in a 10-unit cube, in `op`;
// with `materials`, every other one red.
std::string overlappingSpheres(const std::string& op, bool materials) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-5, 5), r(0.2, 0.7);
  std::ostringstream s;
  s << "let red = diffuse(albedo: [0.8, 0.1, 0.1])\nlet blue = diffuse(albedo: [0.1, 0.1, 0.8])\nscene {\n  " << op
    << " {\n";
  for (int i = 0; i < 400; ++i) {
    s << "    translate([" << u(rng) << ", " << u(rng) << ", " << u(rng) << "]) { sphere(radius: " << r(rng);
    if (materials) s << ", material: " << (i % 2 ? "red" : "blue");
    s << ") }\n";
  }
  s << "  }\n}\n";
  return s.str();
}

// The set's float64 value against the inline code's (brute force) at `count`
// random points in the cube of half-edge `half`: equal to 1e-12, materials
// too. Returns how many points lay near a surface (within 0.3) and inside.
struct Probed {
  int near = 0, inside = 0;
};
Probed expectEqualsInline(const std::string& text, double half, int count, unsigned seed) {
  const CompiledScene data = checked(text, 32), inline_form = checked(text, 0);
  EXPECT_GE(countKind(*data.scene.root, ir::NodeKind::Instances), 1);
  const Evaluator fast(data.scene), brute(inline_form.scene);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-half, half);
  Probed probed;
  for (int i = 0; i < count; ++i) {
    const dvec3 p(u(rng), u(rng), u(rng));
    const EvalResult a = fast.at(p), b = brute.at(p);
    EXPECT_NEAR(a.distance, b.distance, 1e-12 * (1 + std::fabs(b.distance))) << i;
    EXPECT_EQ(a.material, b.material) << i;
    if (testing::Test::HasFailure()) break;
    probed.near += std::fabs(b.distance) < 0.3;
    probed.inside += b.distance < 0;
  }
  return probed;
}

TEST(Instances, HierarchyEqualsBruteForceAtRandomPoints) {
  // The points probe the instances, not only empty space.
  EXPECT_GT(expectEqualsInline(mixedScene(), 8, 4000, 11).near, 100);
}

// Inside overlapping parts the value is the deepest part's: a box's
// distance of 0 inside it is no lower bound there, so the search takes the
// signed box distance (a hard union of 400 overlapping spheres; with the
// unsigned one, 3 points in 4,000 read up to 0.3 too shallow).
TEST(Instances, HierarchyIsExactInsideOverlappingParts) {
  for (bool materials : {false, true})
    EXPECT_GT(expectEqualsInline(overlappingSpheres("union", materials), 5.5, 20000, 3).inside, 1000);
}

// Parts given their own colour the usual way, `union(material: m) { part }`
// (a union of one child), inside or outside their transforms, with or
// without a material of their own inside. `wrapped` false writes the same
// parts with the material the wrappers give (the innermost) as the
// primitive's own argument.
std::string wrappedParts(const std::string& op, bool wrapped) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-4, 4), deg(0, 180);
  std::ostringstream s;
  s << "let red = diffuse(albedo: [0.8, 0.1, 0.1])\nlet blue = diffuse(albedo: [0.1, 0.1, 0.8])\n"
       "let gold = metal(albedo: [0.8, 0.6, 0.2])\nscene {\n  "
    << op << " {\n";
  const char* kinds[] = {"sphere(radius: 0.4", "box(size: [0.6, 0.3, 0.9]", "torus(major: 0.4, minor: 0.1"};
  const char* mats[] = {"red", "blue", "gold"};
  for (int i = 0; i < 200; ++i) {
    const std::string m = mats[(i / 3) % 3];
    const bool own = i % 7 == 0, inner = i % 5 == 1, outer = i % 5 >= 2, outermost = i % 11 == 3;
    const std::string material = own ? "gold" : inner || outer ? m : outermost ? "blue" : "";
    std::string part = kinds[i % 3];
    part += wrapped ? (own ? ", material: gold)" : ")") : (material.empty() ? ")" : ", material: " + material + ")");
    part = "rotate(axis: [1, 2, 3], degrees: " + std::to_string(deg(rng)) + ") { " + part + " }";
    if (wrapped && inner) part = "union(material: " + m + ") { " + part + " }";
    part = "translate([" + std::to_string(u(rng)) + ", " + std::to_string(u(rng)) + ", " + std::to_string(u(rng)) +
           "]) { " + part + " }";
    if (wrapped && outer) part = "union(material: " + m + ") { " + part + " }";
    if (wrapped && outermost) part = "union { union(material: blue) { " + part + " } }";
    s << "    " << part << "\n";
  }
  s << "  }\n}\n";
  return s.str();
}

// Such parts become one set, as if the material were the part's (before,
// each wrapped part stayed code: 600 of them took 100 s to compile): a hard
// union equals the inline code, and a smooth one (blended nearest first as a
// set, in source order as code: docs/language.md) the set of the same parts
// with the materials as arguments, in value and material.
TEST(Instances, PartsWrappedInAMaterialUnionBecomeOneSet) {
  const std::string hard = wrappedParts("union", true);
  EXPECT_EQ(countKind(*checked(hard, 32).scene.root, ir::NodeKind::Instances), 1);
  EXPECT_GT(expectEqualsInline(hard, 5, 6000, 4).near, 500);
  const std::string smooth = wrappedParts("union(smooth: 0.1)", true);
  const CompiledScene wrapped = checked(smooth, 32), direct = checked(wrappedParts("union(smooth: 0.1)", false), 32);
  EXPECT_NE(ir::dump(wrapped.scene).find("instances 200 "), std::string::npos);
  EXPECT_NE(ir::dump(direct.scene).find("instances 200 "), std::string::npos);
  const Evaluator a(wrapped.scene), b(direct.scene);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-5, 5);
  std::set<int> materials;
  for (int i = 0; i < 6000; ++i) {
    const dvec3 p(u(rng), u(rng), u(rng));
    const EvalResult x = a.at(p), y = b.at(p);
    ASSERT_EQ(x.distance, y.distance) << i;
    ASSERT_EQ(x.material, y.material) << i;
    if (x.distance < 0.3) materials.insert(x.material);
  }
  EXPECT_EQ(materials.size(), 4u);  // red, blue, gold and the root's
}

// A dense cloud: 600 spheres in a 4 x 2 x 4 box, so that many grid cells
// hold more than kGridListMax candidates (their reach shrinks) and a few are
// crowded (left to the hierarchy).
// radius 0: varied radii (per-instance parameters), else that radius for all.
// radius 0: varied radii; two_materials: every other sphere red, the rest clay.
std::string denseCloud(int count = 600, double radius = 0, bool two_materials = false) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-2, 2), h(0, 2), r(0.1, 0.3);
  std::ostringstream s;
  s << "camera(position: [0, 5, 9], target: [0, 1, 0], fov: 40)\nsun(direction: [-0.4, 0.8, 0.5])\n"
       "let clay = diffuse(albedo: [0.75, 0.6, 0.5])\nlet red = diffuse(albedo: [0.8, 0.1, 0.1])\n"
       "scene {\n  plane(offset: 0)\n";
  for (int i = 0; i < count; ++i) {
    const double x = u(rng), y = h(rng), z = u(rng), varied = r(rng);
    s << "  translate([" << x << ", " << y << ", " << z << "]) { sphere(radius: " << (radius > 0 ? radius : varied)
      << ", material: " << (two_materials && i % 2 == 1 ? "red" : "clay") << ") }\n";
  }
  s << "}\n";
  return s.str();
}

void collectSets(const ir::NodeRef& n, std::vector<const ir::Node*>& out) {
  if (n->kind == ir::NodeKind::Instances) out.push_back(n.get());
  for (const ir::NodeRef& c : n->children) collectSets(c, out);
}

// The grid's bound (passes/instance_grid.cpp, the shader's arithmetic in
// float64) against brute force over every instance: never above it, and equal
// wherever the nearest instance is within the cell's reach.
TEST(Instances, GridBoundIsALowerBoundAndExactWithinReach) {
  for (const std::string& text : {mixedScene(), denseCloud(), denseCloud(600, 0.2)}) {
    const CompiledScene c = checked(text, 32);
    std::vector<const ir::Node*> sets;
    collectSets(c.scene.root, sets);
    ASSERT_FALSE(sets.empty());
    const Evaluator eval(c.scene);
    std::mt19937 rng(3);
    for (const ir::Node* n : sets) {
      const ir::InstanceSet& set = *n->instances;
      const ir::InstanceGrid& g = set.grid;
      ASSERT_FALSE(g.empty()) << set.origin;
      const dvec3 hi = g.lo + dvec3(g.dims) * g.cell;
      std::uniform_real_distribution<double> ux(g.lo.x - 2, hi.x + 2), uy(g.lo.y - 2, hi.y + 2),
          uz(g.lo.z - 2, hi.z + 2);
      int exact = 0, bounded = 0, crowded = 0, shrunk = 0, in_split = 0;
      for (int i = 0; i < 3000; ++i) {
        const dvec3 p(ux(rng), uy(rng), uz(rng));
        auto one = [&](size_t k) { return eval.instanceDistance(*n, k, p); };
        double brute = 1e300;
        for (size_t k = 0; k < set.size(); ++k) brute = std::min(brute, one(k));
        const double bound = instanceGridBound(set, p, one);
        if (std::isnan(bound)) {
          ++crowded;
          continue;
        }
        ASSERT_LE(bound, brute + 1e-12) << set.origin << " at " << p.x << " " << p.y << " " << p.z;
        if (brute > 0) {
          EXPECT_GT(bound, 0.0);  // a bound, never a false hit
        }
        const bool inside = glm::all(glm::greaterThanEqual(p, g.lo)) && glm::all(glm::lessThan(p, hi));
        if (!inside) continue;
        const ir::GridCellAt at = instanceGridCellAt(g, p);
        const size_t index = at.index;
        shrunk += g.reach[index] < g.margin;
        in_split += index >= size_t(g.dims.x) * g.dims.y * g.dims.z;
        if (brute < g.reach[index]) {
          ASSERT_NEAR(bound, brute, 1e-12) << set.origin;
          ++exact;
        } else {
          ++bounded;
        }
      }
      const size_t split = size_t(std::count(g.count.begin(), g.count.end(), ir::kGridSplit));
      std::printf("%s: %d exact, %d bounded (nearest beyond reach), %d crowded, %d in shrunk cells, "
                  "%d in the sub-cells of %zu split cells\n",
                  set.origin.c_str(), exact, bounded, crowded, shrunk, in_split, split);
      EXPECT_GT(exact, 50);
      // Every split cell has 8 sub-cells after the grid's cells, and a cell
      // is split only if it was crowded (reach 0).
      EXPECT_EQ(g.cells(), size_t(g.dims.x) * g.dims.y * g.dims.z + 8 * split);
      for (size_t c = 0; c < size_t(g.dims.x) * g.dims.y * g.dims.z; ++c)
        if (g.count[c] == ir::kGridSplit) {
          EXPECT_EQ(g.reach[c], 0.0);
        }
    }
  }
}

// Where a ray from p along dir (unit) first meets the sphere (centre, r): 0 inside.
double rayHitSphere(const dvec3& p, const dvec3& dir, const dvec3& centre, double r) {
  const dvec3 q = p - centre;
  const double b = glm::dot(q, dir), c = glm::dot(q, q) - r * r, h = b * b - c;
  if (c <= 0) return 0;
  if (b >= 0 || h < 0) return 1e300;
  return c / (std::sqrt(h) - b);
}

// The root grid's ray skip (instanceGridRaySkip, the shader's arithmetic in
// float64) against the first hit along the ray over every sphere: never
// beyond it, equal to it where a listed sphere is met in the cell, and longer
// than the grid's distance bound (what the march stepped before).
TEST(Instances, GridRaySkipNeverPassesAHit) {
  for (const std::string& text : {denseCloud(), denseCloud(600, 0.2)}) {
    const CompiledScene c = checked(text, 32);
    std::vector<const ir::Node*> sets;
    collectSets(c.scene.root, sets);
    ASSERT_EQ(sets.size(), 1u);
    const ir::Node& n = *sets[0];
    const ir::InstanceSet& set = *n.instances;
    ASSERT_FALSE(set.grid.empty());
    ASSERT_EQ(n.children[0]->primitive, PrimitiveKind::Sphere);
    auto radius = [&](size_t k) {
      return set.param_count > 0 ? set.paramsOf(k)[0] : n.children[0]->args[0].value;
    };
    const Evaluator eval(c.scene);
    const ir::InstanceGrid& g = set.grid;
    const dvec3 hi = g.lo + dvec3(g.dims) * g.cell;
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> ux(g.lo.x, hi.x), uy(g.lo.y, hi.y), uz(g.lo.z, hi.z), s(-1, 1);
    int rays = 0, exact = 0, longer = 0, met = 0;
    for (int i = 0; i < 4000; ++i) {
      const dvec3 p(ux(rng), uy(rng), uz(rng));
      dvec3 dir(s(rng), s(rng), s(rng));
      if (glm::length(dir) < 0.1) continue;
      dir = glm::normalize(dir);
      if (i % 7 == 0) dir = dvec3(0, 0, i % 2 ? 1 : -1);  // along an axis: other components 0
      auto hit = [&](size_t k) { return rayHitSphere(p, dir, -set.instances[k].offset, radius(k)); };
      auto one = [&](size_t k) { return eval.instanceDistance(n, k, p); };
      double first = 1e300;
      for (size_t k = 0; k < set.size(); ++k) first = std::min(first, hit(k));
      const double skip = instanceGridRaySkip(set, p, dir, hit);
      ++rays;
      ASSERT_LE(skip, first + 1e-12) << p.x << " " << p.y << " " << p.z << " dir " << dir.x << " " << dir.y
                                     << " " << dir.z;
      // Short of the cell's exit plus reach, the skip is a listed sphere's hit
      // (g_ray_met): the march takes it as the hit, so it must be the first.
      const double cell_bound = instanceGridRaySkip(set, p, dir, [](size_t) { return 1e300; });
      if (skip < cell_bound) {
        ASSERT_EQ(skip, first) << p.x << " " << p.y << " " << p.z;
        ++met;
      }
      const double bound = instanceGridBound(set, p, one);
      if (std::isnan(bound)) continue;
      exact += skip == first;
      longer += skip > bound + 1e-12;
      ASSERT_GE(skip, std::min(bound, first) - 1e-12);
    }
    std::printf("%s: %d rays, skip = first hit on %d (a listed hit short of the cell bound on %d), longer than"
                " the distance bound on %d\n", set.origin.c_str(), rays, exact, met, longer);
    EXPECT_GT(exact, rays / 10);
    EXPECT_GT(met, rays / 10);
    EXPECT_GT(longer, rays / 2);
  }
}

// Pairs of overlapping spheres, 4 apart: near a surface each blend involves
// two spheres only, so the blend order cannot matter and data = inline
// exactly. Farther out, several pairs lie within the blend radius of each
// other and the polynomial smooth minimum is not associative: the forms may
// differ there, by less than k/4 (each is within k/4 below the plain minimum).
std::string smoothPairs() {
  std::ostringstream s;
  s << "scene {\n  union(smooth: 0.3) {\n";
  for (int i = 0; i < 40; ++i) {
    const double x = (i % 8) * 4.0 - 14, z = (i / 8) * 4.0 - 8;
    s << "    translate([" << x << ", 0, " << z << "]) { sphere(radius: 0.6) }\n";
    s << "    translate([" << x + 0.9 << ", 0.2, " << z << "]) { sphere(radius: 0.5) }\n";
  }
  s << "  }\n}\n";
  return s.str();
}

// The sphere normal's traversal in a crowded cell (sdRootSphereNearest, the
// shader's arithmetic in float64, unlimited visits): a node is skipped when its
// box distance minus the radius is no less than the nearest so far, a bound
// that holds inside spheres too. It finds the nearest sphere (negative inside)
// that brute force over every sphere finds, at points in and around them.
TEST(Instances, SphereNearestTraversalEqualsBruteForce) {
  const CompiledScene c = checked(denseCloud(600, 0.2), 32);
  std::vector<const ir::Node*> sets;
  collectSets(c.scene.root, sets);
  ASSERT_EQ(sets.size(), 1u);
  const ir::InstanceSet& set = *sets[0]->instances;
  const double r = sets[0]->children[0]->args[0].value;
  auto box_distance = [](const dvec3& p, const ir::BvhNode& b) {
    return glm::length(glm::max(glm::max(b.box.lo - p, p - b.box.hi), dvec3(0)));
  };
  std::mt19937 rng(17);
  std::uniform_int_distribution<size_t> pick(0, set.size() - 1);
  std::uniform_real_distribution<double> s(-1, 1);
  int inside = 0, skipped = 0;
  for (int i = 0; i < 3000; ++i) {
    const dvec3 p = -set.instances[pick(rng)].offset + dvec3(s(rng), s(rng), s(rng)) * (1.5 * r);
    double brute = 1e30;
    for (const ir::Instance& inst : set.instances) brute = std::min(brute, glm::length(p + inst.offset) - r);
    double field = 1e30;
    std::vector<std::pair<std::uint32_t, double>> stack{{0, box_distance(p, set.nodes[0])}};
    while (!stack.empty()) {
      const auto [ni, d] = stack.back();
      stack.pop_back();
      if (d - r >= field) {
        ++skipped;
        continue;
      }
      const ir::BvhNode& node = set.nodes[ni];
      if (node.count == 0) {
        const std::uint32_t lc = ni + 1, rc = node.first;
        const double dl = box_distance(p, set.nodes[lc]), dr = box_distance(p, set.nodes[rc]);
        const bool left_near = dl <= dr;
        if (std::max(dl, dr) - r < field) stack.push_back({left_near ? rc : lc, std::max(dl, dr)});
        if (std::min(dl, dr) - r < field) stack.push_back({left_near ? lc : rc, std::min(dl, dr)});
      } else {
        for (std::uint32_t k = 0; k < node.count; ++k)
          field = std::min(field, glm::length(p + set.instances[node.first + k].offset) - r);
      }
    }
    EXPECT_EQ(field, brute) << i;
    inside += brute < 0;
  }
  std::printf("sphere nearest traversal: %d of 3000 points inside a sphere, %d nodes skipped\n", inside, skipped);
  EXPECT_GT(inside, 500);
  EXPECT_GT(skipped, 3000);
}

// The hit sphere remembered (SDFC_HAS_SPHERE_HIT): when the march ends on a
// listed sphere's analytic hit x, surfaceNormal takes that sphere's radial
// direction at c = x + dir * ahead instead of looking up the nearest sphere at
// c (slot order, strict <, as the shader; brute force in crowded cells).
// Same sphere, same arithmetic: the same normal bits. A different sphere B can
// be nearer at c only if c lies inside B, which x (the first hit) does not: B's
// surface then passes within `ahead` of x, at an intersection curve of two
// spheres, where either sphere's normal is the surface's. Duplicated centres
// pick the first listed in both (strict <) and give the same normal anyway.
TEST(Instances, MetSphereNormalEqualsTheLookups) {
  const CompiledScene c = checked(denseCloud(600, 0.2), 32);
  std::vector<const ir::Node*> sets;
  collectSets(c.scene.root, sets);
  ASSERT_EQ(sets.size(), 1u);
  const ir::InstanceSet& set = *sets[0]->instances;
  const double r = sets[0]->children[0]->args[0].value;
  const ir::InstanceGrid& g = set.grid;
  ASSERT_FALSE(g.empty());
  const dvec3 hi = g.lo + dvec3(g.dims) * g.cell;
  auto radial = [&](size_t k, const dvec3& at) { return glm::normalize(at + set.instances[k].offset); };
  // The lookup's sphere at c: the cell's list in slot order, nearest centre.
  auto lookup = [&](const dvec3& at) -> long {
    if (glm::any(glm::lessThan(at, g.lo)) || glm::any(glm::greaterThan(at, hi))) return -2;
    const size_t index = instanceGridCellAt(g, at).index;
    double qq_min = 1e300;
    long best = -1;
    const bool crowded = g.count[index] < 0;
    const size_t n = crowded ? set.size() : size_t(g.count[index]);
    for (size_t k = 0; k < n; ++k) {
      const size_t e = crowded ? k : g.entries[g.first[index] + k];
      const dvec3 q = at + set.instances[e].offset;
      if (glm::dot(q, q) < qq_min) {
        qq_min = glm::dot(q, q);
        best = long(e);
      }
    }
    return best;
  };
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> ux(g.lo.x, hi.x), uy(g.lo.y, hi.y), uz(g.lo.z, hi.z), s(-1, 1);
  const double ahead = 1e-3;
  int met = 0, same = 0, edge = 0;
  for (int i = 0; i < 20000; ++i) {
    const dvec3 p(ux(rng), uy(rng), uz(rng));
    dvec3 dir(s(rng), s(rng), s(rng));
    if (glm::length(dir) < 0.1) continue;
    dir = glm::normalize(dir);
    size_t met_k = 0;
    double met_t = 1e300;
    auto hit = [&](size_t k) {
      const double t = rayHitSphere(p, dir, -set.instances[k].offset, r);
      if (t < met_t) {  // the shader's slot order: the first strictly nearer
        met_t = t;
        met_k = k;
      }
      return t;
    };
    const double skip = instanceGridRaySkip(set, p, dir, hit);
    const double cell_bound = instanceGridRaySkip(set, p, dir, [](size_t) { return 1e300; });
    if (!(skip < cell_bound) || skip <= 0) continue;  // not a met sphere (g_ray_met false)
    ++met;
    ASSERT_EQ(skip, met_t);
    const dvec3 x = p + dir * skip, at = x + dir * ahead;
    const long k = lookup(at);
    ASSERT_GE(k, 0);
    if (size_t(k) == met_k) {
      ++same;
      EXPECT_EQ(radial(met_k, at), radial(size_t(k), at));
      continue;
    }
    // Another sphere nearer at c: c is inside it, x is not (the first hit), so
    // its surface passes within `ahead` of x.
    const double dx = glm::length(x + set.instances[size_t(k)].offset) - r;
    EXPECT_GE(dx, -1e-12) << i;
    EXPECT_LE(dx, ahead) << i;
    ++edge;
  }
  std::printf("met spheres: %d rays, the lookup's sphere on %d, another at an intersection curve on %d\n", met,
              same, edge);
  EXPECT_GT(met, 1000);
  EXPECT_GE(same, met - met / 100);  // intersection curves are rare
}

TEST(Instances, SmoothUnionBlendsTheNearOnesLikeTheInlineForm) {
  const CompiledScene data = checked(smoothPairs(), 32);
  const CompiledScene inline_form = checked(smoothPairs(), 0);
  ASSERT_EQ(countKind(*data.scene.root, ir::NodeKind::Instances), 1);
  const Evaluator fast(data.scene), brute(inline_form.scene);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> x(-16, 16), y(-2, 2), z(-10, 10);
  int near = 0;
  for (int i = 0; i < 3000; ++i) {
    const dvec3 p(x(rng), y(rng), z(rng));
    const double a = fast.distance(p), b = brute.distance(p);
    if (b < 0.8) {
      ASSERT_NEAR(a, b, 1e-12) << p.x << " " << p.y << " " << p.z;
      ++near;
    } else {
      ASSERT_NEAR(a, b, 0.3 / 4) << p.x << " " << p.y << " " << p.z;
    }
  }
  EXPECT_GT(near, 100);
}

TEST(Instances, FilePositionsEqualTheListAndFewBecomeAUnion) {
  const std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "sdfc_instances";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "points.csv") << "# x, y, z, scale\nx,y,z\n0, 0, 0\n2 1 0\n-2;0;1;0.5\n";
  const std::string list = "scene { instances(positions: [[0, 0, 0], [2, 1, 0], [-2, 0, 1, 0.5]]) { box(size: 1) } }";
  const std::string file = "scene { instances(positions: file(\"points.csv\")) { box(size: 1) } }";
  CompileOptions options;
  options.instancing.threshold = 2;  // data form
  Diagnostics d1, d2;
  const CompiledScene a = checkSource("list.sdf", list, options, d1);
  const CompiledScene b = checkSource((dir / "scene.sdf").string(), file, options, d2);
  ASSERT_TRUE(a.ok) << d1.format();
  ASSERT_TRUE(b.ok) << d2.format();
  EXPECT_EQ(countKind(*b.scene.root, ir::NodeKind::Instances), 1);
  options.instancing.threshold = 32;  // three copies: a union
  Diagnostics d3;
  const CompiledScene c = checkSource((dir / "scene.sdf").string(), file, options, d3);
  EXPECT_EQ(countKind(*c.scene.root, ir::NodeKind::Instances), 0);
  const Evaluator ea(a.scene), eb(b.scene), ec(c.scene);
  for (const dvec3 p : {dvec3(0, 0, 0), dvec3(1.2, 0.5, 0), dvec3(-2, 0.4, 1), dvec3(5, 5, 5)}) {
    EXPECT_DOUBLE_EQ(ea.distance(p), eb.distance(p));
    EXPECT_DOUBLE_EQ(ea.distance(p), ec.distance(p));
  }
  EXPECT_NEAR(ea.distance(dvec3(-2, 0, 1)), -0.25, 1e-12);  // the half-size box
}

std::string errorsOf(const std::string& path, const std::string& text) {
  Diagnostics diags;
  const CompiledScene c = checkSource(path, text, CompileOptions{}, diags);  // owns the source
  EXPECT_TRUE(diags.hasErrors()) << text;
  return diags.format();
}

TEST(Instances, BadPositionsAreErrorsWithLocations) {
  const std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "sdfc_instances_bad";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "bad.csv") << "1, 2, 3\n1, 2\n4, five, 6\n7, 8, 9, -1\n";
  const std::string scene = (dir / "s.sdf").string();
  std::string e = errorsOf(scene, "scene {\n  instances(positions: file(\"missing.csv\")) { sphere(radius: 1) }\n}");
  EXPECT_NE(e.find("s.sdf:2:29: error: cannot read"), std::string::npos) << e;
  e = errorsOf(scene, "scene { instances(positions: file(\"bad.csv\")) { sphere(radius: 1) } }");
  // Each at its place in the CSV (point_file_test.cpp has the rules).
  EXPECT_NE(e.find("bad.csv:2:1: error: expected 3 or 4 numbers"), std::string::npos) << e;
  EXPECT_NE(e.find("bad.csv:3:4: error: 'five' is not a decimal number"), std::string::npos) << e;
  EXPECT_NE(e.find("bad.csv:4:10: error: scale must be positive"), std::string::npos) << e;
  e = errorsOf("t.sdf", "scene { instances(positions: [[0, 0, 0], [1, 2]]) { sphere(radius: 1) } }");
  EXPECT_NE(e.find("t.sdf:1:42: error: each position must be"), std::string::npos) << e;
  e = errorsOf("t.sdf", "scene { instances(positions: [[0, 0, time]]) { sphere(radius: 1) } }");
  EXPECT_NE(e.find("each position must be a constant"), std::string::npos) << e;
  e = errorsOf("t.sdf", "scene { instances(positons: [[0, 0, 0]]) { sphere(radius: 1) } }");
  EXPECT_NE(e.find("did you mean 'positions'?"), std::string::npos) << e;
  e = errorsOf("t.sdf", "scene { instances(positions: [[0, 0, 0]]) }");
  EXPECT_NE(e.find("needs a block"), std::string::npos) << e;
  e = errorsOf("t.sdf", "scene {\n  translate(file(\"x.csv\")) { sphere(radius: 1) } }");
  EXPECT_NE(e.find("t.sdf:2:13: error: 'file' may only give"), std::string::npos) << e;
  e = errorsOf("t.sdf", "scene { sphere(radius: \"1\") }");
  EXPECT_NE(e.find("t.sdf:1:24: error: 'radius' of 'sphere' must be a number, not a string"), std::string::npos) << e;
  e = errorsOf("t.sdf", "let a = \"1\"\nscene { sphere(radius: a) }");
  EXPECT_NE(e.find("a string is no value here: strings only name files"), std::string::npos) << e;
  e = errorsOf("t.sdf", "scene { sphere(radius: \"1) }");
  EXPECT_NE(e.find("unterminated string"), std::string::npos) << e;
}

class InstancesGpu : public ::testing::Test {
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
  static VulkanContext* context_;

  static CompiledScene compiled(const std::string& text, int threshold, bool kernel = true) {
    CompileOptions options;
    options.instancing.threshold = threshold;
    options.emit.with_kernel = kernel;
    options.produce_spirv = kernel;
    options.emit.bounding_volumes = false;
    options.emit.march.image_height = 36;
    // The points probed lie about the world origin: keep the scene there (the
    // default camera stands among the parts, which would move it to the
    // camera's frame; passes/rebase.cpp).
    options.camera_frame = false;
    Diagnostics diags;
    CompiledScene c = compileSource("test.sdf", text, options, diags);
    EXPECT_TRUE(c.ok) << diags.format();
    return c;
  }
};
VulkanContext* InstancesGpu::context_ = nullptr;

TEST_F(InstancesGpu, ShaderDistancesMatchTheEvaluator) {
  const CompiledScene c = compiled(mixedScene(), 32, false);
  ASSERT_EQ(c.emitted.stats.instance_sets, 1);  // one mixed set
  ASSERT_FALSE(c.emitted.scene_data.empty());
  const std::string source = test::pointShaderSource(c.emitted);
  const SpirvResult spirv = glslToSpirv(source, ShaderStage::Fragment, "instances.points.frag");
  ASSERT_TRUE(spirv.ok()) << spirv.log;
  const test::GpuPoints gpu = test::runPoints(*context_, spirv.words, glm::vec3(0), glm::vec3(7.5f), 42, 0,
                                              c.emitted.scene_data);
  const Evaluator eval(c.scene);
  // Far from every box (relative to the box's size) the shader returns the
  // least box distance instead: never above the distance; near surfaces exact.
  const double tolerance = 64.0 / 8388608.0 * 16;  // the float32 bound of gpu_equivalence_test, scale 16
  double worst = 0;
  int material_mismatch = 0, near = 0, lower = 0;
  for (size_t i = 0; i < gpu.points.size(); ++i) {
    const EvalResult e = eval.at(dvec3(gpu.points[i]));
    EXPECT_LE(gpu.distances[i], e.distance + tolerance) << i;
    if (std::fabs(e.distance) < 0.05) {
      worst = std::max(worst, std::fabs(e.distance - gpu.distances[i]));
      ++near;
    } else if (gpu.distances[i] < e.distance - tolerance) {
      ++lower;
      EXPECT_GT(gpu.distances[i], 0.0) << i;
      continue;  // the material of a far point is not resolved
    }
    // Materials may differ only where two surfaces are equally near (float32).
    if (gpu.materials[i] != e.material) {
      if (material_mismatch < 5)
        std::printf("material at %g %g %g: gpu %d cpu %d (d %g)\n", gpu.points[i].x, gpu.points[i].y,
                    gpu.points[i].z, gpu.materials[i], e.material, e.distance);
      ++material_mismatch;
    }
  }
  std::printf("instances on the GPU: worst |d_gpu - d_cpu| = %.3g over %d points near surfaces; "
              "%d far points got a box bound; %d material mismatches\n",
              worst, near, lower, material_mismatch);
  EXPECT_GT(near, 50);
  EXPECT_LT(worst, tolerance);
  EXPECT_LE(material_mismatch, 2);
}

// Spheres of varied radii (a molecule): with no material of their own the
// radius rides in the offset's w (records of one vec4, which the blend lists
// copy); with materials it keeps a vec4 of its own. Either way, in a hard and
// a smooth union (through their grids) and a blend that moves with time
// (through the hierarchy, whose boxes are signed distances), the shader's
// distances and materials are the evaluator's, inside the parts too.
TEST_F(InstancesGpu, SphereRadiiInTheOffsetMatchTheEvaluator) {
  for (const char* op : {"union", "union(smooth: 0.08)", "union(smooth: 0.08 + 0.01 * sin(time))"})
    for (bool materials : {false, true}) {
      const CompiledScene c = compiled(overlappingSpheres(op, materials), 32, false);
      ASSERT_EQ(c.emitted.stats.instance_sets, 1) << op;
      EXPECT_EQ(c.emitted.glsl.find("Grid of") == std::string::npos, std::string(op).find("time") != std::string::npos)
          << op;
      const std::string said = materials ? "records of 2 vec4" : "records of 1 vec4";
      EXPECT_NE(c.emitted.glsl.find(said), std::string::npos) << op << ": " << said;
      const std::string source = test::pointShaderSource(c.emitted);
      const SpirvResult spirv = glslToSpirv(source, ShaderStage::Fragment, "radii.points.frag");
      ASSERT_TRUE(spirv.ok()) << spirv.log;
      const test::GpuPoints gpu =
          test::runPoints(*context_, spirv.words, glm::vec3(0), glm::vec3(6.0f), 42, 0, c.emitted.scene_data);
      const Evaluator eval(c.scene);
      const double tolerance = 64.0 / 8388608.0 * 16;
      int near = 0, inside = 0, material_mismatch = 0;
      for (size_t i = 0; i < gpu.points.size(); ++i) {
        const EvalResult e = eval.at(dvec3(gpu.points[i]));
        EXPECT_LE(gpu.distances[i], e.distance + tolerance) << op << " " << i;
        inside += e.distance < 0;
        if (std::fabs(e.distance) >= 0.1) continue;
        ++near;
        EXPECT_NEAR(gpu.distances[i], e.distance, tolerance) << op << " " << i;
        // Without materials the evaluator says -1 (none), the shader 0 (the default).
        if (materials) material_mismatch += gpu.materials[i] != e.material;
      }
      EXPECT_GT(near, 50) << op;
      EXPECT_GT(inside, 50) << op;
      EXPECT_LE(material_mismatch, 2) << op;
    }
}

std::string boxField(int count) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-10, 10), h(0, 3);
  std::ostringstream s;
  s << "camera(position: [0, 14, 30], target: [0, 0, 0], fov: 40)\nsun(direction: [-0.4, 0.8, 0.5])\n"
       "scene {\n  plane(offset: -0.5)\n";
  for (int i = 0; i < count; ++i)
    s << "  translate([" << u(rng) << ", " << h(rng) << ", " << u(rng) << "]) { box(size: [0.8, 0.8, 0.8]) }\n";
  s << "}\n";
  return s.str();
}

TEST_F(InstancesGpu, ImageEqualsTheInlineFormAndStaysUnderTheLoopCap) {
  const std::string text = boxField(200);
  const CompiledScene data = compiled(text, 32), inline_form = compiled(text, 0);
  ASSERT_EQ(data.emitted.stats.instance_sets, 1);
  ASSERT_EQ(inline_form.emitted.stats.instance_sets, 0);
  RenderOverrides o;
  o.width = 64;
  o.height = 36;
  o.spp = 8;
  Renderer rd(*context_, data);
  Renderer ri(*context_, inline_form);
  const FloatImage a = rd.render(cameraFor(data.scene), renderSettingsFor(data, o)).color;
  const FloatImage b = ri.render(cameraFor(inline_form.scene), renderSettingsFor(inline_form, o)).color;
  double sum_a = 0, sum_b = 0, diff = 0;
  for (size_t i = 0; i < a.rgba.size(); i += 4)
    for (int ch = 0; ch < 3; ++ch) {
      sum_a += a.rgba[i + ch];
      sum_b += b.rgba[i + ch];
      diff += std::fabs(a.rgba[i + ch] - b.rgba[i + ch]);
    }
  // Same seeds and samples: only float32 roundings of the placements differ.
  std::printf("data vs inline: mean %.6f vs %.6f, mean |diff| %.3g\n", sum_a / (a.rgba.size() * 0.75),
              sum_b / (b.rgba.size() * 0.75), diff / (a.rgba.size() * 0.75));
  EXPECT_NEAR(sum_a, sum_b, 1e-3 * sum_b);
  EXPECT_LT(diff / sum_b, 2e-3);

  // The loop counter (every kernel and traversal iteration) stays below the cap.
  o.view = gpu::kViewIterations;
  const FloatImage it = rd.render(cameraFor(data.scene), renderSettingsFor(data, o)).color;
  float most = 0;
  for (size_t i = 0; i < it.rgba.size(); i += 4) most = std::max(most, it.rgba[i]);
  std::printf("most loop iterations in a pixel: %.0f\n", most);
  EXPECT_GT(most, 100);
  EXPECT_LT(most, float(gpu::kLavapipeLoopCap));
}

// A dense cloud through the grid (lists cut to kGridListMax, shrunk reaches,
// crowded cells answered by the hierarchy) renders as the inline union does:
// no ray stops early on a bound, and none passes a sphere by a ray skip (the
// root grid's; analytic hits when every sphere has one radius). With one
// radius the lists are fixed slots without a loop, and with one material too
// the normal reads no material (SDFC_HAS_SPHERE_MATERIAL); two materials read
// theirs as before.
TEST_F(InstancesGpu, DenseCloudThroughTheGridEqualsTheInlineForm) {
  for (double radius : {0.0, 0.2, -0.2}) {
    const bool two_materials = radius < 0;
    radius = std::fabs(radius);
    const std::string text = denseCloud(300, radius, two_materials);
    const CompiledScene data = compiled(text, 32), inline_form = compiled(text, 0);
    ASSERT_EQ(data.emitted.stats.instance_sets, 1);
    EXPECT_EQ(data.emitted.stats.features.count("SDFC_HAS_RAY_SKIP"), 1u);
    EXPECT_EQ(data.emitted.glsl.find("_one_ray(") != std::string::npos, radius > 0);
    EXPECT_EQ(data.emitted.stats.features.count("SDFC_HAS_SPHERE_MATERIAL"), radius > 0 && !two_materials ? 1u : 0u);
    // Fixed slots: one material packs 8 centres in 6 vec4; two keep a record (w: material) each.
    EXPECT_EQ(data.emitted.glsl.find(two_materials ? "ci * 8 + 7]" : "ci * 6 + 5]") != std::string::npos, radius > 0);
    RenderOverrides o;
    o.width = 64;
    o.height = 36;
    o.spp = 8;
    Renderer rd(*context_, data);
    Renderer ri(*context_, inline_form);
    const FloatImage a = rd.render(cameraFor(data.scene), renderSettingsFor(data, o)).color;
    const FloatImage b = ri.render(cameraFor(inline_form.scene), renderSettingsFor(inline_form, o)).color;
    double sum_b = 0, diff = 0, worst = 0;
    for (size_t i = 0; i < a.rgba.size(); i += 4) {
      double pixel = 0;
      for (int ch = 0; ch < 3; ++ch) {
        sum_b += b.rgba[i + ch];
        pixel += std::fabs(a.rgba[i + ch] - b.rgba[i + ch]);
      }
      diff += pixel;
      worst = std::max(worst, pixel);
    }
    std::printf("dense cloud (radius %g%s), grid vs inline: mean |diff| %.3g of mean %.3g, worst pixel %.3g\n",
                radius, two_materials ? ", two materials" : "", diff / (a.rgba.size() * 0.75), sum_b / (b.rgba.size() * 0.75), worst);
    EXPECT_LT(diff / sum_b, 5e-3);
  }
}

// Primary depth (the depth view: the unjittered ray through each pixel
// centre) of a one-radius point cloud over a ground plane, against the first
// hit over every sphere and the plane solved in closed form in float64; at
// `pixels` (x, y), or at every pixel when none are given.
struct DepthCheck {
  int on_spheres = 0, off = 0;  // off: more than 1e-4 relative from the exact hit
  double worst = 0;
  int out_of_steps = 0;  // primary rays that used the whole step budget (of every pixel)
};
DepthCheck checkCloudDepth(VulkanContext& context, const CompiledScene& data, double radius, uint32_t w,
                           uint32_t h, std::vector<std::pair<uint32_t, uint32_t>> pixels = {}) {
  std::vector<const ir::Node*> sets;
  collectSets(data.scene.root, sets);
  EXPECT_EQ(sets.size(), 1u);
  const ir::InstanceSet& set = *sets[0]->instances;
  RenderOverrides o;
  o.width = w;
  o.height = h;
  o.spp = 1;
  o.view = gpu::kViewDepth;
  Renderer r(context, data);
  const CameraDesc camera = cameraFor(data.scene);
  const RenderOutput out = r.render(camera, renderSettingsFor(data, o));
  DepthCheck c;
  const float budget = static_cast<float>(data.emitted.limits.max_steps);
  for (size_t i = 0; i < size_t(w) * h; ++i) c.out_of_steps += out.albedo_steps.rgba[i * 4 + 3] >= budget;
  if (pixels.empty())
    for (uint32_t y = 0; y < h; ++y)
      for (uint32_t x = 0; x < w; ++x) pixels.push_back({x, y});
  // The kernel's cameraRay in float64, from the same float basis.
  const gpu::FrameParams f = makeFrameParams(camera, w, h, 0);
  const dvec3 ro(f.cam_origin), right(f.cam_right), up(f.cam_up), forward(f.cam_forward);
  const double tan_half = f.cam_origin.w, aspect = double(w) / h;
  for (const auto& [x, y] : pixels) {
    const double nx = 2.0 * (x + 0.5) / w - 1, ny = 1 - 2.0 * (y + 0.5) / h;
    const dvec3 rd = glm::normalize(forward + (nx * aspect * tan_half) * right + (ny * tan_half) * up);
    double exact = rd.y < 0 ? -ro.y / rd.y : 1e300;
    bool sphere = false;
    for (size_t k = 0; k < set.size(); ++k) {
      const double t = rayHitSphere(ro, rd, -set.instances[k].offset, radius);
      if (t < exact) {
        exact = t;
        sphere = true;
      }
    }
    const double rel = std::fabs(out.color.rgba[(size_t(y) * w + x) * 4] - exact) / exact;
    c.on_spheres += sphere;
    c.worst = std::max(c.worst, rel);
    c.off += rel > 1e-4;
  }
  std::printf("%zu pixels, %d on spheres: %d off by more than 1e-4 relative, worst %.3g; %d rays out of steps\n",
              pixels.size(), c.on_spheres, c.off, c.worst, c.out_of_steps);
  return c;
}

// The point cloud's march (fixed slots and the cell step, docs/design/large_scenes.md)
// is exact on a dense cloud with split cells.
TEST_F(InstancesGpu, PointCloudDepthIsTheExactFirstHit) {
  const CompiledScene data = compiled(denseCloud(600, 0.2), 32);
  ASSERT_EQ(data.emitted.stats.features.count("SDFC_HAS_SPHERE_HIT"), 1u);
  std::vector<const ir::Node*> sets;
  collectSets(data.scene.root, sets);
  ASSERT_EQ(sets.size(), 1u);
  const std::vector<std::int32_t>& count = sets[0]->instances->grid.count;
  EXPECT_GT(std::count(count.begin(), count.end(), ir::kGridSplit), 0);
  const DepthCheck c = checkCloudDepth(*context_, data, 0.2, 160, 90);
  EXPECT_GT(c.on_spheres, 160 * 90 / 10);
  EXPECT_EQ(c.off, 0);
}

// bench/large_scenes.py's points: CPython's random.Random(1).uniform, whose
// Mersenne Twister is seeded by init_by_array([1]) and whose doubles take 53
// bits from two draws, so this is the benchmark's very cloud.
class PythonRandom {
 public:
  explicit PythonRandom(std::uint32_t seed) {
    mt_[0] = 19650218u;
    for (int i = 1; i < 624; ++i) mt_[i] = 1812433253u * (mt_[i - 1] ^ (mt_[i - 1] >> 30)) + i;
    int i = 1;
    for (int k = 624; k > 0; --k) {  // init_by_array with the one key word `seed`
      mt_[i] = (mt_[i] ^ ((mt_[i - 1] ^ (mt_[i - 1] >> 30)) * 1664525u)) + seed;
      if (++i >= 624) { mt_[0] = mt_[623]; i = 1; }
    }
    for (int k = 623; k > 0; --k) {
      mt_[i] = (mt_[i] ^ ((mt_[i - 1] ^ (mt_[i - 1] >> 30)) * 1566083941u)) - i;
      if (++i >= 624) { mt_[0] = mt_[623]; i = 1; }
    }
    mt_[0] = 0x80000000u;
  }
  double uniform(double a, double b) {
    const double x = ((next() >> 5) * 67108864.0 + (next() >> 6)) * (1.0 / 9007199254740992.0);
    return a + (b - a) * x;
  }

 private:
  std::uint32_t next() {
    if (index_ >= 624) {
      for (int k = 0; k < 624; ++k) {
        const std::uint32_t y = (mt_[k] & 0x80000000u) | (mt_[(k + 1) % 624] & 0x7fffffffu);
        mt_[k] = mt_[(k + 397) % 624] ^ (y >> 1) ^ ((y & 1u) ? 0x9908b0dfu : 0u);
      }
      index_ = 0;
    }
    std::uint32_t y = mt_[index_++];
    y ^= y >> 11;
    y ^= (y << 7) & 0x9d2c5680u;
    y ^= (y << 15) & 0xefc60000u;
    return y ^ (y >> 18);
  }
  std::uint32_t mt_[624];
  int index_ = 624;
};

// The benchmark's million spheres (40 x 7.5 x 40, radius 0.0464) take the
// fixed slots too: their grid is capped at 800,000 cells and the packed slots
// (8 centres in 6 vec4) keep all the scene's data within the 128 MiB storage
// buffer range every Vulkan device has. At 640x360 no primary ray runs out of
// steps: 5 did when a cell step shorter than float resolves at t left the ray
// standing at a cell's face (a cell of tiny reach). The depth is exact: 400
// pixels against float64 over every sphere, and those 5.
TEST_F(InstancesGpu, AMillionSpheresTakeFixedSlotsWithinTheStorageRange) {
  // Per process: worktrees running this suite at once share the temporary folder.
  const std::filesystem::path dir =
      std::filesystem::path(testing::TempDir()) / ("sdfc_million_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  {
    PythonRandom rng(1);
    std::ofstream f(dir / "points.csv");
    f << "x,y,z\n";
    char line[96];
    for (int i = 0; i < 1000000; ++i) {
      const double x = rng.uniform(-20, 20), y = rng.uniform(0.5, 8), z = rng.uniform(-20, 20);
      std::snprintf(line, sizeof line, "%.5f,%.5f,%.5f\n", x, y, z);
      if (i == 0) {
        EXPECT_STREQ(line, "-14.62543,6.85575,10.55098\n");  // the benchmark's first point
      }
      f << line;
    }
  }
  const double radius = 0.0464159;
  const std::string text =
      "camera(position: [0, 26, 48], target: [0, 2, 0], fov: 45)\nsun(direction: [-0.4, 0.8, 0.5])\n"
      "let clay = diffuse(albedo: [0.75, 0.6, 0.5])\nscene {\n  plane(offset: 0)\n"
      "  instances(positions: file(\"points.csv\"), material: clay) { sphere(radius: 0.0464159) }\n}\n";
  CompileOptions options;
  options.emit.bounding_volumes = false;
  options.emit.march.image_height = 360;
  Diagnostics diags;
  const CompiledScene data = compileSource((dir / "scene.sdf").string(), text, options, diags);
  std::error_code ignored;
  std::filesystem::remove_all(dir, ignored);  // read by now; 30 MB a run
  ASSERT_TRUE(data.ok) << diags.format();
  std::vector<const ir::Node*> sets;
  collectSets(data.scene.root, sets);
  ASSERT_EQ(sets.size(), 1u);
  const ir::InstanceGrid& grid = sets[0]->instances->grid;
  EXPECT_LE(size_t(grid.dims.x) * grid.dims.y * grid.dims.z, 800000u);
  std::printf("a million spheres: %zu bytes of scene data, %zu grid cells\n",
              data.emitted.scene_data.size() * sizeof(float), grid.cells());
  EXPECT_LE(data.emitted.scene_data.size() * sizeof(float), size_t(128) << 20);
  // Fixed slots: straight-line loads of a cell's 6 vec4 (no loop over a list).
  EXPECT_NE(data.emitted.glsl.find("ci * 6 + 5]"), std::string::npos);
  std::vector<std::pair<uint32_t, uint32_t>> pixels = {{132, 258}, {133, 258}, {134, 258}, {130, 259}, {132, 259}};
  std::mt19937 pick(11);
  while (pixels.size() < 405) pixels.push_back({pick() % 640, pick() % 360});
  const DepthCheck c = checkCloudDepth(*context_, data, radius, 640, 360, pixels);
  EXPECT_EQ(c.out_of_steps, 0);
  EXPECT_GT(c.on_spheres, 100);
  EXPECT_EQ(c.off, 0);
}

// A point listed 60 times is one sphere: the grid lists it once (else every
// cell near it is crowded and left to the hierarchy, whose visits run out in
// such a pile: without this rule 61 of 14,400 pixels of such a scene stopped
// more than 1% short), so the march stays exact there too. One pixel may be
// off: pixel (123, 40) stops 0.7% short, its ray not out of steps; the scene
// has 4 crowded octants, left to the hierarchy, near which that can happen
// (docs/design/large_scenes.md, "A tight clump").
TEST_F(InstancesGpu, RepeatedPointsAreListedOnceAndStayExact) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> layer(-5, 5);
  std::ostringstream s;
  s << "camera(position: [0, 6, 9], target: [0, 2, 0], fov: 40)\nsun(direction: [-0.4, 0.8, 0.5])\n"
       "let clay = diffuse(albedo: [0.75, 0.6, 0.5])\nscene {\n  plane(offset: 0)\n"
       "  instances(material: clay, positions: [";
  for (int i = 0; i < 60; ++i) s << "[1, 2, 3], ";
  for (int i = 0; i < 400; ++i) s << "[" << layer(rng) << ", 2, " << layer(rng) << "]" << (i < 399 ? ", " : "");
  s << "]) { sphere(radius: 0.3) }\n}\n";
  const CompiledScene data = compiled(s.str(), 32);
  ASSERT_EQ(data.emitted.stats.features.count("SDFC_HAS_SPHERE_HIT"), 1u);
  std::vector<const ir::Node*> sets;
  collectSets(data.scene.root, sets);
  ASSERT_EQ(sets.size(), 1u);
  const ir::InstanceSet& set = *sets[0]->instances;
  const ir::InstanceGrid& g = set.grid;
  size_t lists_with_the_point = 0;
  for (size_t c = 0; c < g.cells(); ++c) {
    int copies = 0;
    for (std::int32_t k = 0; k < g.count[c]; ++k)
      copies += set.instances[g.entries[g.first[c] + k]].offset == dvec3(-1, -2, -3);
    EXPECT_LE(copies, 1) << "cell " << c;
    lists_with_the_point += copies;
  }
  EXPECT_GT(lists_with_the_point, 0u);
  const DepthCheck c = checkCloudDepth(*context_, data, 0.3, 160, 90);
  EXPECT_LE(c.off, 1);
}

// A pixel's value does not depend on the pixels beside it in the lanes:
// the cell step (taken only when all lanes of a group may take it) and the
// march body do the same for a lane that may. The same absolute pixels drawn
// one column and one row over (FrameParams.tile_x/y, so each group holds
// other neighbours) are bit-identical.
TEST_F(InstancesGpu, PointCloudPixelsDoNotDependOnTheirLaneNeighbours) {
  const CompiledScene data = compiled(denseCloud(3000, 0.1), 32);
  ASSERT_EQ(data.emitted.stats.features.count("SDFC_HAS_SPHERE_HIT"), 1u);
  Renderer r(*context_, data);
  const uint32_t w = 192, h = 108;
  gpu::FrameParams p = makeFrameParams(cameraFor(data.scene), w, h, 0);
  p.seed = 3;
  p.view = gpu::kViewBeauty;
  p.max_bounces = 3;
  p.light_samples = 1;
  p.sample_base = 0;
  p.sample_count = 8;
  FloatImage a, b, nd, as;
  r.renderPass(p, 60, a, nd, as);
  p.tile_x = 1;
  p.tile_y = 1;
  r.renderPass(p, 60, b, nd, as);
  size_t differing = 0, compared = 0;
  for (uint32_t y = 0; y + 1 < h; ++y)
    for (uint32_t x = 0; x + 1 < w; ++x)
      for (int ch = 0; ch < 3; ++ch) {
        ++compared;
        differing += a.rgba[((size_t(y) + 1) * w + x + 1) * 4 + ch] != b.rgba[(size_t(y) * w + x) * 4 + ch];
      }
  std::printf("%zu of %zu values differ\n", differing, compared);
  EXPECT_EQ(differing, 0u);
}

// Where a ray from p along dir (unit) first meets the axis-aligned box of
// half size `half` about `centre` (p outside it).
double rayHitBox(const dvec3& p, const dvec3& dir, const dvec3& centre, const dvec3& half) {
  double t0 = 0, t1 = 1e300;
  for (int a = 0; a < 3; ++a) {
    if (dir[a] == 0) {
      if (std::fabs(p[a] - centre[a]) > half[a]) return 1e300;
      continue;
    }
    const double ta = (centre[a] - half[a] - p[a]) / dir[a], tb = (centre[a] + half[a] - p[a]) / dir[a];
    t0 = std::max(t0, std::min(ta, tb));
    t1 = std::min(t1, std::max(ta, tb));
  }
  return t0 <= t1 ? t0 : 1e300;
}

// Issue 28: 45 copies on a 1.5 grid and one more far away. The set's grid
// spanned the far copy (cells of 950 at 1e6, each holding all 45: every step
// through the hierarchy) and the hit tolerance's floor was a millionth of the
// set's extent (1.0 at 1e6): the grid drew a slab, and from 1e10 nothing.
// Now the far copy is a group of its own and the floor a millionth of one
// copy. Spheres, boxes and a file() point set, the far copy at 1e3 to 1e30:
// every pixel's primary hit and depth against the exact first hit in float64.
TEST_F(InstancesGpu, OneFarCopyLeavesTheGroupExact) {
  const std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "sdfc far copy";
  std::filesystem::create_directories(dir);
  std::vector<dvec3> centres;
  for (int i = 0; i < 45; ++i) centres.push_back({(i % 9) * 1.5, (i / 9 % 3) * 1.5, (i / 27) * 1.5 - 1.5});
  const uint32_t w = 64, h = 36;
  for (const char* shape : {"sphere", "box", "file"}) {
    for (double far : {1e3, 3e3, 1e6, 1e10, 1e30}) {
      std::ostringstream s;
      s << "camera(position: [6, 6, 12], target: [6, 1, 0], fov: 45)\nsun(direction: [-0.4, 0.8, 0.5])\nscene {\n";
      centres.push_back({far, 0, 0});
      if (std::string(shape) == "file") {
        std::ofstream csv(dir / "points.csv");
        for (const dvec3& c : centres) csv << c.x << "," << c.y << "," << c.z << "\n";
        s << "  instances(positions: file(\"points.csv\")) { sphere(radius: 0.5) }\n";
      } else {
        for (const dvec3& c : centres)
          s << "  translate([" << c.x << ", " << c.y << ", " << c.z << "]) { "
            << (std::string(shape) == "box" ? "box(size: [0.8, 0.8, 0.8])" : "sphere(radius: 0.5)") << " }\n";
      }
      s << "}\n";
      CompileOptions options;
      options.emit.bounding_volumes = false;
      options.emit.march.image_height = h;
      Diagnostics diags;
      const CompiledScene c = compileSource((dir / "scene.sdf").string(), s.str(), options, diags);
      ASSERT_TRUE(c.ok) << diags.format();
      ASSERT_EQ(c.scene.origin, dvec3(0));  // the camera is near the origin
      EXPECT_EQ(c.emitted.stats.instance_sets, 1) << shape << " " << far;
      RenderOverrides o;
      o.width = w;
      o.height = h;
      o.spp = 1;
      o.view = gpu::kViewDepth;
      Renderer r(*context_, c);
      const CameraDesc camera = cameraFor(c.scene);
      const RenderOutput out = r.render(camera, renderSettingsFor(c, o));
      const gpu::FrameParams f = makeFrameParams(camera, w, h, 0);
      const dvec3 ro(f.cam_origin), right(f.cam_right), up(f.cam_up), forward(f.cam_forward);
      const double tan_half = f.cam_origin.w, aspect = double(w) / h;
      int hits = 0, disagree = 0, off = 0;
      double worst = 0;
      for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
          const double nx = 2.0 * (x + 0.5) / w - 1, ny = 1 - 2.0 * (y + 0.5) / h;
          const dvec3 rd = glm::normalize(forward + (nx * aspect * tan_half) * right + (ny * tan_half) * up);
          double exact = 1e300;
          for (const dvec3& centre : centres)
            exact = std::min(exact, std::string(shape) == "box" ? rayHitBox(ro, rd, centre, dvec3(0.4))
                                                                : rayHitSphere(ro, rd, centre, 0.5));
          const float depth = out.normal_depth.at(x, y)[3];
          const bool hit = depth >= 0, exact_hit = exact < 1e300;
          hits += exact_hit;
          disagree += hit != exact_hit;
          if (hit && exact_hit) {
            const double rel = std::fabs(depth - exact) / exact;
            worst = std::max(worst, rel);
            off += rel > 1e-4;
          }
        }
      std::printf("%s, far copy at %g: %d exact hits, %d pixels hit where none is or miss one, %d off by "
                  "more than 1e-4 relative (worst %.3g)\n", shape, far, hits, disagree, off, worst);
      EXPECT_GT(hits, int(w * h) / 10);
      EXPECT_EQ(disagree, 0) << shape << " " << far;
      EXPECT_EQ(off, 0) << shape << " " << far;
      centres.pop_back();
    }
  }
}

// --count-event: the kernel's per-pixel event counts (docs/design/large_scenes.md,
// decomposition) in the iterations view's green channel. One path per pixel
// at 1 spp: exactly one primary segment, and it always hits (the ground
// plane is under every pixel); bounce and shadow rays at most max_bounces
// each; shading events on spheres at most the hits; at most a lookup per
// march iteration; without the flag the shader has no counters.
TEST_F(InstancesGpu, CountEventsCountEachPathsRays) {
  const std::string text = denseCloud(300, 0.2);
  EXPECT_EQ(compiled(text, 32).emitted.glsl.find("countEvent"), std::string::npos);
  auto mean = [&](const std::string& event) {
    CompileOptions options;
    options.instancing.threshold = 32;
    options.emit.bounding_volumes = false;
    options.emit.march.image_height = 36;
    options.emit.count_event = event;
    Diagnostics diags;
    const CompiledScene c = compileSource("test.sdf", text, options, diags);
    EXPECT_TRUE(c.ok) << diags.format();
    EXPECT_EQ(c.emitted.stats.features.count("SDFC_COUNT_EVENTS"), 1u);
    RenderOverrides o;
    o.width = 64;
    o.height = 36;
    o.spp = 1;
    o.view = gpu::kViewIterations;
    Renderer r(*context_, c);
    const FloatImage it = r.render(cameraFor(c.scene), renderSettingsFor(c, o)).color;
    double sum = 0;
    for (size_t i = 0; i < it.rgba.size(); i += 4) sum += it.rgba[i + 1];
    return sum / double(it.rgba.size() / 4);
  };
  EXPECT_EQ(mean("primary.segments"), 1.0);
  EXPECT_EQ(mean("primary.hits"), 1.0);
  const double bounces = mean("bounce.segments"), shadows = mean("shadow.segments");
  const double shading = mean("normal.segments"), hits = mean("all.hits");
  const double iterations = mean("primary.iterations"), lookups = mean("primary.lookups");
  std::printf("per pixel: bounce rays %.3f, shadow rays %.3f, all hits %.3f, sphere shading %.3f, "
              "primary iterations %.3f, lookups %.3f\n", bounces, shadows, hits, shading, iterations, lookups);
  EXPECT_GT(bounces, 0.5);
  EXPECT_LE(bounces, 3.0);
  EXPECT_GT(shadows, 0.5);
  EXPECT_LE(shadows, 3.0);
  EXPECT_GT(shading, 0.1);
  EXPECT_LE(shading, hits);
  EXPECT_GT(iterations, 0.3);  // rays that miss the cloud's box take no steps
  EXPECT_LE(lookups, iterations);  // a march iteration reads at most one cell (none outside the grid)
  EXPECT_GT(lookups, 0.5);
}

}  // namespace
}  // namespace sdfc
