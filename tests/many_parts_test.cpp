// Scenes of many distinct parts (issue 46): hard and smooth unions of mixed,
// rotated primitives of varied sizes, split into several instance sets, and
// smooth blends of many spheres. Each hit pixel of a primary depth render must
// lie on the float64 surface within the pixel's footprint, with no surface
// before it on the ray; a lower bound (out of visits, a box distance) may
// shorten a step but never end a march as a hit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <functional>
#include <random>
#include <set>
#include <sstream>
#include <string>

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

// `kinds` primitive kinds x `per_kind` parts, each rotated about a random
// axis and sized at random, in a ball; `op` is the combining operator, e.g.
// "union(smooth: 0.1)". With `carve`, the parts are subtracted from a box.
std::string mixedParts(int kinds, int per_kind, const std::string& op, unsigned seed, bool carve = false) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1), size(0.15, 0.45), angle(0, 180);
  const int n = kinds * per_kind;
  const double radius = 0.55 * std::cbrt(double(n));
  std::ostringstream s;
  s << "camera(position: [" << 1.4 * radius << ", " << 1.1 * radius << ", " << 2.4 * radius
    << "], target: [0, 0, 0], fov: 45)\nsun(direction: [0.5, 1, 0.3])\nscene {\n";
  if (carve) s << "  subtract {\n    box(size: [" << 1.6 * radius << ", " << 1.6 * radius << ", " << 1.6 * radius << "])\n";
  s << "  " << op << " {\n";
  const char* names[] = {"sphere", "box", "capsule", "cylinder", "torus"};
  for (int i = 0; i < n; ++i) {
    dvec3 p;
    do p = dvec3(u(rng), u(rng), u(rng));
    while (glm::dot(p, p) > 1);
    p *= radius;
    const double sz = size(rng);
    const dvec3 axis(u(rng), u(rng) + 1.5, u(rng));
    s << "    translate([" << p.x << ", " << p.y << ", " << p.z << "]) { rotate(axis: [" << axis.x << ", " << axis.y
      << ", " << axis.z << "], degrees: " << angle(rng) << ") { ";
    switch (i % kinds) {
      case 0: s << names[0] << "(radius: " << sz << ")"; break;
      case 1: s << names[1] << "(size: [" << sz * 1.5 << ", " << sz << ", " << sz * 0.8 << "])"; break;
      case 2: s << names[2] << "(radius: " << sz * 0.4 << ", height: " << sz * 1.5 << ")"; break;
      case 3: s << names[3] << "(radius: " << sz * 0.6 << ", height: " << sz * 1.4 << ")"; break;
      default: s << names[4] << "(major: " << sz * 0.8 << ", minor: " << sz * 0.25 << ")"; break;
    }
    s << " } }\n";
  }
  s << "  }\n" << (carve ? "  }\n" : "") << "}\n";
  return s.str();
}

// Distinct parametric parts (every call has its own arguments, so each is a
// template of its own), rotated boxes of varied sizes and tori, in three
// materials: chess pieces on a board, as a new user writes them.
std::string pieces(int count, double smooth) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> s(0.9, 1.1), angle(0, 90);
  std::ostringstream o;
  o << "camera(position: [6, 7, 11], target: [0, 0.5, 0], fov: 45)\nsun(direction: [0.5, 1, 0.3])\n"
       "let white = diffuse(albedo: [0.9, 0.9, 0.85])\nlet black = diffuse(albedo: [0.1, 0.1, 0.1])\n"
       "let wood = diffuse(albedo: [0.6, 0.4, 0.2])\n"
       "let pawn(s) = union {\n  translate([0, 0.15 * s, 0]) { cylinder(radius: 0.3 * s, height: 0.3 * s) }\n"
       "  translate([0, 0.7 * s, 0]) { sphere(radius: 0.22 * s) }\n}\n"
       "let rook(s) = subtract {\n  translate([0, 0.5 * s, 0]) { cylinder(radius: 0.3 * s, height: s) }\n"
       "  translate([0, s, 0]) { box(size: [0.7 * s, 0.2 * s, 0.1 * s]) }\n}\n"
       "scene {\n  union(smooth: " << smooth << ") {\n";
  for (int i = 0; i < count; ++i) {
    const double x = (i % 8) - 3.5, z = (i / 8) - 3.5;
    const char* m = i % 3 == 0 ? "white" : i % 3 == 1 ? "black" : "wood";
    o << "    translate([" << x << ", 0, " << z << "], material: " << m << ") { ";
    switch (i % 4) {
      case 0: o << "pawn(" << s(rng) << ")"; break;
      case 1: o << "rook(" << s(rng) << ")"; break;
      case 2: o << "rotate(axis: [0, 1, 0], degrees: " << angle(rng) << ") { box(size: [0.4, " << 0.5 * s(rng)
                << ", 0.3]) }"; break;
      default: o << "translate([0, 0.2, 0]) { torus(major: " << 0.3 * s(rng) << ", minor: 0.08) }"; break;
    }
    o << " }\n";
  }
  o << "  }\n}\n";
  return o.str();
}

CompiledScene checkedParts(const std::string& text, int threshold) {
  CompileOptions options;
  options.instancing.threshold = threshold;
  options.produce_spirv = false;
  options.emit.with_kernel = false;
  Diagnostics diags;
  CompiledScene c = compileSource("pieces.sdf", text, options, diags);
  EXPECT_TRUE(c.ok) << diags.format();
  return c;
}

int countSets(const ir::Node& n) {
  int count = n.kind == ir::NodeKind::Instances;
  for (const ir::NodeRef& c : n.children) count += countSets(*c);
  return count;
}

// Primitives of several kinds become one mixed set (one search instead of
// one per kind), in a smooth union with a blend grid; definitions stay code
// (passes/instancing.cpp says why). The float64 value equals the inline
// code's: exactly for a hard union (min is order-free), within the blend's
// reordering for a smooth one (the set blends nearest first, the code in
// written order; sequential blends of three parts within k depend on it).
TEST(ManyParts, MixedSetEqualsTheInlineCode) {
  for (double smooth : {0.0, 0.05}) {
    const CompiledScene data = checkedParts(pieces(64, smooth), 32), inline_form = checkedParts(pieces(64, smooth), 0);
    ASSERT_TRUE(data.ok && inline_form.ok);
    EXPECT_EQ(countSets(*data.scene.root), 1);
    EXPECT_EQ(countSets(*inline_form.scene.root), 0);
    const std::string dump = ir::dump(data.scene);
    EXPECT_NE(dump.find("instances 32 (data form: union of 32 box, torus"), std::string::npos) << dump;
    EXPECT_EQ(dump.find("blend grid") != std::string::npos, smooth > 0) << dump;
    const Evaluator fast(data.scene), brute(inline_form.scene);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-5, 5), h(-0.5, 2);
    int near = 0;
    for (int i = 0; i < 3000; ++i) {
      const dvec3 p(u(rng), h(rng), u(rng));
      const EvalResult a = fast.at(p), b = brute.at(p);
      ASSERT_NEAR(a.distance, b.distance, smooth > 0 ? 0.25 * smooth : 1e-12 * (1 + std::fabs(b.distance)))
          << p.x << " " << p.y << " " << p.z;
      if (smooth == 0) EXPECT_EQ(a.material, b.material) << i;
      near += std::fabs(b.distance) < 0.2;
    }
    EXPECT_GT(near, 100);
  }
}

// Parts of the given kinds (every other one rotated, with `scaled` some scaled), overlapping
// in a 6-unit cube, combined by `form`: a union, holes cut from a box, a
// union intersected with a ball, or two unions (one moved) in a union.
std::string overlappingParts(const std::vector<std::string>& kinds, int n, const std::string& form, unsigned seed,
                             bool scaled = true) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-3, 3), size(0.2, 0.9), unit(-1, 1), angle(0, 180), scale(0.5, 1.5);
  std::vector<std::string> parts;
  for (int i = 0; i < n; ++i) {
    const std::string& k = kinds[i % kinds.size()];
    const double z = size(rng);
    std::ostringstream o;
    if (k == "sphere") o << "sphere(radius: " << z << ")";
    if (k == "box") o << "box(size: [" << z << ", " << 0.7 * z << ", " << 1.3 * z << "])";
    if (k == "capsule") o << "capsule(radius: " << 0.3 * z << ", height: " << z << ")";
    if (k == "cylinder") o << "cylinder(radius: " << 0.5 * z << ", height: " << z << ")";
    if (k == "torus") o << "torus(major: " << 0.7 * z << ", minor: " << 0.2 * z << ")";
    std::string shape = o.str();
    if (i % 2 == 1)
      shape = "rotate(axis: [" + std::to_string(unit(rng)) + ", " + std::to_string(unit(rng)) + ", " +
              std::to_string(unit(rng) + 1.5) + "], degrees: " + std::to_string(angle(rng)) + ") { " + shape + " }";
    const double factor = scale(rng);
    if (scaled && i % 5 == 2) shape = "scale(" + std::to_string(factor) + ") { " + shape + " }";
    parts.push_back("translate([" + std::to_string(u(rng)) + ", " + std::to_string(u(rng)) + ", " +
                    std::to_string(u(rng)) + "]) { " + shape + " }");
  }
  auto join = [&](size_t from, size_t to) {
    std::string all;
    for (size_t i = from; i < to; ++i) all += "    " + parts[i] + "\n";
    return all;
  };
  std::string body;
  if (form == "union") body = "union {\n" + join(0, n) + "  }";
  if (form == "smooth") body = "union(smooth: 0.1) {\n" + join(0, n) + "  }";
  if (form == "smooth holes") body = "subtract {\n    box(size: [5, 5, 5])\n    union(smooth: 0.1) {\n" + join(0, n) + "    }\n  }";
  if (form == "holes") body = "subtract {\n    box(size: [5, 5, 5])\n" + join(0, n) + "  }";
  if (form == "intersect") body = "intersect {\n    sphere(radius: 3.2)\n    union {\n" + join(0, n) + "    }\n  }";
  if (form == "nested")
    body = "union {\n    union {\n" + join(0, n / 2) + "    }\n    translate([0.3, 0, 0]) { union {\n" +
           join(n / 2, n) + "    } }\n  }";
  return "scene {\n  " + body + "\n}\n";
}

// Sets (one kind or mixed, rotated, scaled, overlapping) equal the inline
// code at points inside the parts as well as outside them, for every hard
// form a set is made from: the search takes a box's signed distance, since
// one of 0 inside it is no lower bound on the deeper parts there (with it,
// `eval` read up to 0.5 off inside 6 of 10 such scenes).
TEST(ManyParts, SetsEqualTheInlineCodeInsideAndOut) {
  const std::vector<std::vector<std::string>> kinds = {
      {"sphere"}, {"box"}, {"torus", "cylinder"}, {"sphere", "box", "capsule", "cylinder", "torus"}};
  unsigned seed = 1;
  for (const char* form : {"union", "holes", "intersect", "nested"})
    for (const std::vector<std::string>& k : kinds)
      for (int n : {70, 200}) {
        const std::string text = overlappingParts(k, n, form, seed++);
        const CompiledScene data = checkedParts(text, 32), inline_form = checkedParts(text, 0);
        ASSERT_TRUE(data.ok && inline_form.ok);
        ASSERT_GE(countSets(*data.scene.root), 1) << form << " " << n;
        ASSERT_EQ(countSets(*inline_form.scene.root), 0);
        const Evaluator fast(data.scene), brute(inline_form.scene);
        std::mt19937 rng(seed);
        std::uniform_real_distribution<double> u(-3.5, 3.5);
        int inside = 0;
        for (int i = 0; i < 1500; ++i) {
          const dvec3 p(u(rng), u(rng), u(rng));
          const EvalResult a = fast.at(p), b = brute.at(p);
          ASSERT_NEAR(a.distance, b.distance, 1e-12 * (1 + std::fabs(b.distance)))
              << form << " of " << n << " " << k[0] << "...: " << p.x << " " << p.y << " " << p.z;
          inside += b.distance < 0;
        }
        EXPECT_GT(inside, 10) << form << " " << n;
      }
}

// A block with many holes: the shapes a hard subtract cuts away are a
// union, which becomes data; the value equals the inline code's.
const ir::Node* findSet(const ir::Node& n) {
  if (n.kind == ir::NodeKind::Instances) return &n;
  for (const ir::NodeRef& c : n.children)
    if (const ir::Node* s = findSet(*c)) return s;
  return nullptr;
}

// A blend grid lists each cell kind-major, then by member: lanes on
// neighbouring cells then branch on the same kind at the same place in their
// lists more often (docs/design/large_scenes.md, "Cost per part").
TEST(ManyParts, BlendGridListsAreInKindOrder) {
  std::string text = mixedParts(5, 60, "union", 7);
  text.replace(text.find("  union {"), 9, "  union(smooth: 0.1) {");
  const CompiledScene c = checkedParts(text, 32);
  ASSERT_TRUE(c.ok);
  const ir::Node* set = findSet(*c.scene.root);
  ASSERT_NE(set, nullptr);
  const ir::InstanceSet& members = *set->instances;
  const ir::InstanceGrid& g = members.grid;
  ASSERT_TRUE(g.blend);
  int mixed = 0;
  for (size_t cell = 0; cell < g.count.size(); ++cell) {
    bool kinds = false;
    for (std::int32_t j = 1; j < g.count[cell]; ++j) {
      const std::uint32_t a = g.entries[g.first[cell] + j - 1], b = g.entries[g.first[cell] + j];
      const std::int32_t ta = members.instances[a].templ, tb = members.instances[b].templ;
      ASSERT_TRUE(ta < tb || (ta == tb && a < b)) << "cell " << cell << ", place " << j;
      kinds = kinds || ta != tb;
    }
    mixed += kinds;
  }
  EXPECT_GT(mixed, 20);  // lists of several kinds: the order above was tested
}

// A mixed set of rotated parts keeps each record's template index in its
// placement's free slot: with rotations alone, a unit quaternion and then
// (offset, template), 3 vec4 a record with the box's 4 parameters; with
// scales too, a 3x4 map and (scale, material, template, 0), 5 vec4 (not 6).
TEST(ManyParts, MixedRecordsCarryTheirTemplateInThePlacement) {
  for (bool scaled : {false, true})
    for (const char* op : {"union", "union(smooth: 0.1)"}) {
      std::string text = mixedParts(5, 60, op, 3);
      if (scaled) {
        // Every part scaled: `{ rotate(` gains a `scale(1.25) {` and its closing brace.
        for (size_t at = 0; (at = text.find("{ rotate(", at)) != std::string::npos; at += 20) {
          text.replace(at, 9, "{ scale(1.25) { rotate(");
          const size_t end = text.find(" } }\n", at);
          text.replace(end, 5, " } } }\n");
        }
      }
      const CompiledScene c = checkedParts(text, 32);
      ASSERT_TRUE(c.ok);
      const ir::Node* set = findSet(*c.scene.root);
      ASSERT_NE(set, nullptr);
      const ir::InstanceSet& members = *set->instances;
      ASSERT_EQ(set->children.size(), 5u) << op;
      ASSERT_EQ(members.param_count, 4) << op;  // the box's size and rounding
      const std::string& glsl = c.emitted.glsl;
      const size_t stride = scaled ? 5 : 3, templ_at = scaled ? 3 * 4 + 2 : 1 * 4 + 3;
      const std::string said = "records of " + std::to_string(stride) + " vec4 at sd_data[";
      const size_t at = glsl.find(said);
      ASSERT_NE(at, std::string::npos) << op << ": " << said;
      ASSERT_NE(glsl.find(scaled ? "int t = int(e.z);" : "int t = int(r1.w);"), std::string::npos) << op;
      const size_t records = std::stoul(glsl.substr(at + said.size()));
      const std::vector<float>& data = c.emitted.scene_data;
      ASSERT_LE((records + members.size() * stride) * 4, data.size());
      std::set<std::int32_t> seen;
      for (size_t i = 0; i < members.size(); ++i) {
        ASSERT_EQ(data[(records + i * stride) * 4 + templ_at], float(members.instances[i].templ)) << op << ", record " << i;
        seen.insert(members.instances[i].templ);
      }
      EXPECT_EQ(seen.size(), 5u) << op;
    }
}

// A smooth set's blend grid (passes/blend_grid.cpp) lists, per cell, every
// member that can come within k of the nearest: the evaluator's value through
// the lists equals, bit for bit, the blend of all members nearest first, at
// points inside the grid and beyond it, for every kind mixed, rotated and of
// varied sizes, from tens to thousands of parts and blend radii up to
// beyond a part's size. (One member left out of one list fails it.)
TEST(ManyParts, BlendGridListsEveryMemberThatCounts) {
  for (int per_kind : {8, 60, 400})
    for (double k : {0.02, 0.1, 0.4}) {
      std::string text = mixedParts(5, per_kind, "union", unsigned(per_kind));
      text.replace(text.find("  union {"), 9, "  union(smooth: " + std::to_string(k) + ") {");
      const CompiledScene c = checkedParts(text, 32);
      ASSERT_TRUE(c.ok);
      const ir::Node* set = findSet(*c.scene.root);
      ASSERT_NE(set, nullptr);
      ASSERT_TRUE(set->instances->grid.blend) << ir::dump(c.scene);
      const ir::InstanceSet& members = *set->instances;
      const Evaluator eval(c.scene);
      const ir::InstanceGrid& g = members.grid;
      const dvec3 lo = g.lo - 0.2 * (dvec3(g.dims) * g.cell), hi = g.lo + 1.2 * (dvec3(g.dims) * g.cell);
      std::mt19937 rng(per_kind);
      std::uniform_real_distribution<double> u(0, 1);
      std::uniform_int_distribution<size_t> pick(0, members.size() - 1);
      int near = 0, far = 0;
      for (int i = 0; i < 6000; ++i) {
        // Where lists are tested hardest: near parts (where blends act) and
        // at corners of (sub-)cells, the farthest from the centres the lists
        // are proven from; and anywhere, beyond the grid too.
        dvec3 p = lo + dvec3(u(rng), u(rng), u(rng)) * (hi - lo);
        if (i % 3 == 0) {
          const Aabb b = instanceBounds(members, pick(rng), *set).grow(k);
          p = b.lo + dvec3(u(rng), u(rng), u(rng)) * (b.hi - b.lo);
        } else if (i % 3 == 1) {
          const Aabb b = instanceBounds(members, pick(rng), *set).grow(k);
          const dvec3 q = b.lo + dvec3(u(rng), u(rng), u(rng)) * (b.hi - b.lo);
          const double half = 0.5 * g.cell;
          p = g.lo + glm::round((q - g.lo) / half) * half + (dvec3(u(rng), u(rng), u(rng)) - 0.5) * 1e-9;
        }
        std::vector<double> values;
        for (size_t j = 0; j < members.size(); ++j) values.push_back(eval.instanceDistance(*set, j, p));
        std::sort(values.begin(), values.end());
        double want = std::numeric_limits<double>::infinity();
        for (double v : values) want = smoothMin(want, v, k);
        const double got = eval.evalNode(*set, p, -1).distance;
        // Where the kernel steps on a bound (beyond the grid, or a cell far
        // from every part), the bound must not exceed the blend.
        const dvec3 top = g.lo + dvec3(g.dims) * g.cell;
        const dvec3 out = glm::max(glm::max(g.lo - p, p - top), dvec3(0));
        if (out != dvec3(0)) {
          ASSERT_LE(glm::length(out) + g.margin, want) << "beyond the grid";
        } else {
          const ir::GridCellAt at = instanceGridCellAt(g, p);
          const dvec3 in = glm::min(at.q, 1.0 - at.q);
          if (g.count[at.index] == 0) {
            ++far;
            ASSERT_LE(g.reach[at.index] + at.size * std::max(0.0, std::min({in.x, in.y, in.z})), want) << "far cell";
          }
        }
        ASSERT_EQ(got, want) << per_kind * 5 << " parts, k " << k << ", at " << p.x << " " << p.y << " " << p.z;
        near += std::fabs(want) < 0.1;
      }
      EXPECT_GT(near, 20) << per_kind * 5 << " parts, k " << k;
      if (per_kind >= 60) EXPECT_GT(far, 20) << per_kind * 5 << " parts, k " << k;
    }
}

// The blend grid's z slices are listed on several threads and joined in z
// order: any thread count builds the same grid, bit for bit, including a
// build that gives up (over its evaluation budget: a blend radius spanning
// the set).
TEST(ManyParts, BlendGridIsTheSameOnAnyNumberOfThreads) {
  for (double k : {0.1, 3.0}) {
    std::string text = mixedParts(5, 400, "union", 11);
    text.replace(text.find("  union {"), 9, "  union(smooth: " + std::to_string(k) + ") {");
    const CompiledScene c = checkedParts(text, 32);
    ASSERT_TRUE(c.ok);
    const ir::Node* set = findSet(*c.scene.root);
    ASSERT_NE(set, nullptr);
    const Evaluator eval(c.scene);
    auto build = [&](unsigned threads) {
      ir::InstanceSet members = *set->instances;
      const bool built = buildBlendGrid(members, *set, k, [&](size_t i, const dvec3& p) {
        return eval.instanceDistance(*set, i, p);
      }, threads);
      return std::make_pair(built, members.grid);
    };
    const auto [one_built, one] = build(1);
    EXPECT_EQ(one_built, k < 1) << "k " << k;
    for (unsigned threads : {2u, 3u, 8u}) {
      const auto [built, g] = build(threads);
      SCOPED_TRACE("k " + std::to_string(k) + ", " + std::to_string(threads) + " threads");
      EXPECT_EQ(built, one_built);
      EXPECT_EQ(g.dims, one.dims);
      EXPECT_EQ(g.first, one.first);
      EXPECT_EQ(g.count, one.count);
      EXPECT_EQ(g.reach, one.reach);
      EXPECT_EQ(g.entries, one.entries);
      EXPECT_EQ(g.longest, one.longest);
      EXPECT_EQ(g.splits, one.splits);
    }
    if (!one_built) continue;
    EXPECT_GT(one.splits, 0) << "no octants: the join's renumbering is untested";
    // The numbering of one pass over the cells in z, y, x order: a list's
    // entries follow the lists before it, a split cell's octants the octants
    // before them (depth first), as the single-threaded build numbered them.
    size_t entries = 0, octants = size_t(one.dims.x) * one.dims.y * one.dims.z;
    std::function<bool(size_t)> walk = [&](size_t c) {
      if (one.count[c] == ir::kGridSplit) {
        if (one.first[c] != octants) return false;
        const size_t sub = octants;
        octants += 8;
        for (size_t o = 0; o < 8; ++o)
          if (!walk(sub + o)) return false;
        return true;
      }
      if (one.first[c] != entries || one.count[c] < 0) return false;
      entries += size_t(one.count[c]);
      return true;
    };
    for (size_t c = 0, cells = octants; c < cells; ++c) ASSERT_TRUE(walk(c)) << "cell " << c;
    EXPECT_EQ(entries, one.entries.size());
    EXPECT_EQ(octants, one.count.size());
  }
}

TEST(ManyParts, HolesCutAwayBecomeData) {
  const std::string text = mixedParts(5, 40, "union", 5, true);
  const std::string flat = [&] {
    // The same cuts as direct children of the subtract (how people write it).
    std::string t = text;
    t.erase(t.find("  union {\n"), 10);
    t.erase(t.rfind("  }\n  }"), 4);
    return t;
  }();
  const CompiledScene data = checkedParts(flat, 32), inline_form = checkedParts(flat, 0);
  ASSERT_TRUE(data.ok && inline_form.ok);
  EXPECT_EQ(countSets(*data.scene.root), 1);
  const Evaluator fast(data.scene), brute(inline_form.scene);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-4, 4);
  int inside = 0;
  for (int i = 0; i < 3000; ++i) {
    const dvec3 p(u(rng), u(rng), u(rng));
    const double a = fast.distance(p), b = brute.distance(p);
    ASSERT_NEAR(a, b, 1e-12 * (1 + std::fabs(b))) << p.x << " " << p.y << " " << p.z;
    inside += b < 0;
  }
  EXPECT_GT(inside, 300);
}

class ManyPartsGpu : public ::testing::Test {
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

  struct Verdict {
    int hits = 0, off = 0, early = 0, missed = 0, sets = 0;
    double worst = 0;
  };

  // Renders `text`'s primary depth at w x h and checks every pixel against
  // the float64 evaluator (see the file's comment).
  static Verdict check(const std::string& text, uint32_t w = 160, uint32_t h = 90) {
    CompileOptions options;
    // SDFC_DEBUG_THRESHOLD=0 renders the parts as inline code (the reference
    // the data form must match); SDFC_DEBUG_PIXELS=1 prints the first early hits.
    if (const char* t = std::getenv("SDFC_DEBUG_THRESHOLD")) options.instancing.threshold = std::atoi(t);
    options.emit.bounding_volumes = false;
    options.emit.march.image_height = h;
    Diagnostics diags;
    const CompiledScene c = compileSource("many_parts.sdf", text, options, diags);
    EXPECT_TRUE(c.ok) << diags.format();
    Verdict v;
    if (!c.ok) return v;
    v.sets = c.emitted.stats.instance_sets;
    RenderOverrides o;
    o.width = int(w);
    o.height = int(h);
    o.spp = 1;
    o.view = gpu::kViewDepth;
    Renderer r(*context_, c);
    const CameraDesc camera = cameraFor(c.scene);
    const RenderOutput out = r.render(camera, renderSettingsFor(c, o));
    const gpu::FrameParams f = makeFrameParams(camera, w, h, 0);
    const dvec3 ro(f.cam_origin), right(f.cam_right), up(f.cam_up), forward(f.cam_forward);
    const double tan_half = f.cam_origin.w, aspect = double(w) / h;
    const Evaluator eval(c.scene);
    // A pixel's footprint at distance t: its width there.
    auto footprint = [&](double t) { return std::max(t, 1e-3) * 2 * tan_half / h; };
    const double reach = 4 * glm::length(ro);
    for (uint32_t y = 0; y < h; ++y)
      for (uint32_t x = 0; x < w; ++x) {
        const double nx = 2.0 * (x + 0.5) / w - 1, ny = 1 - 2.0 * (y + 0.5) / h;
        const dvec3 rd = glm::normalize(forward + (nx * aspect * tan_half) * right + (ny * tan_half) * up);
        // The float64 march (a smooth blend and rotations are 1-Lipschitz): a
        // stop within a quarter footprint of the surface is a hit when the ray
        // goes clearly inside (half a footprint) within 4 footprints after it,
        // else a near miss, passed by half a footprint.
        double t64 = 0;
        bool hit64 = false;
        for (int i = 0; i < 4000 && t64 < reach && !hit64; ++i) {
          const double d = eval.distance(ro + rd * t64), fp = footprint(t64);
          if (d >= 0.25 * fp) {
            t64 += d;
            continue;
          }
          for (int j = 0; j <= 8 && !hit64; ++j) hit64 = eval.distance(ro + rd * (t64 + 0.5 * j * fp)) < -0.5 * fp;
          if (!hit64) t64 += std::max(d, 0.5 * fp);
        }
        const double depth = out.normal_depth.at(x, y)[3];
        if (depth < 0) {
          // A miss where float64 goes clearly inside (not a grazing touch).
          if (hit64) ++v.missed;
          continue;
        }
        ++v.hits;
        const double fp = footprint(depth);
        const double field = eval.distance(ro + rd * depth);
        v.worst = std::max(v.worst, std::fabs(field) / fp);
        if (std::fabs(field) > fp) ++v.off;
        if (hit64 && t64 < depth - 2 * fp) {  // a surface clearly before the hit
          if (v.early < 3 && std::getenv("SDFC_DEBUG_PIXELS"))
            std::printf("early pixel %u,%u: t64 %g depth %g fp %g f(t64) %g f(t64+fp) %g f(t64+2fp) %g\n", x, y, t64,
                        depth, fp, eval.distance(ro + rd * t64), eval.distance(ro + rd * (t64 + footprint(t64))),
                        eval.distance(ro + rd * (t64 + 2 * footprint(t64))));
          ++v.early;
        }
      }
    return v;
  }

  // `skims`: the share of hit pixels allowed to pass a part they skim (1 in
  // 100; rounded parts, skimmed more often, 1 in 50 with inline code too).
  static void expectExact(const std::string& what, const std::string& text, int skims = 100) {
    const Verdict v = check(text);
    std::printf("[ parts    ] %s: %d instance sets, %d hit pixels, %d off the surface (worst %.3g footprints), "
                "%d with a surface before them, %d missed\n",
                what.c_str(), v.sets, v.hits, v.off, v.worst, v.early, v.missed);
    EXPECT_GT(v.hits, 500) << what;
    EXPECT_EQ(v.off, 0) << what;
    // A ray that skims a part within the hit band passes it (pathtrace.glsl's
    // near-miss rule): the same few pixels with the parts as inline code
    // (--instance-threshold 0), which is not what this file tests.
    EXPECT_LE(v.early, v.hits / skims) << what;
    EXPECT_LE(v.missed, 2) << what;  // a grazing silhouette may differ by a pixel
  }
};

VulkanContext* ManyPartsGpu::context_ = nullptr;

// A clump so dense that more than kGridListMax parts touch an octant of a
// crowded cell: such octants list up to kGridListMaxCrowded parts instead of
// leaving their points to the hierarchy (instance_grid.cpp), and stay exact.
TEST_F(ManyPartsGpu, CrowdedOctantsTakeLongListsAndStayExact) {
  if (context_->loop_cap) GTEST_SKIP() << "the driver caps loops: traversals are rationed (docs/large_scenes.md)";
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1), size(0.2, 0.5), angle(0, 180);
  std::ostringstream s;
  s << "camera(position: [3, 2.5, 5], target: [0, 0, 0], fov: 40)\nsun(direction: [0.5, 1, 0.3])\nscene {\n  union {\n";
  for (int i = 0; i < 1500; ++i) {
    dvec3 p;
    do p = dvec3(u(rng), u(rng), u(rng));
    while (glm::dot(p, p) > 1);
    p *= 1.3;
    const double sz = size(rng);
    s << "    translate([" << p.x << ", " << p.y << ", " << p.z << "]) { rotate(axis: [" << u(rng) << ", 1, " << u(rng)
      << "], degrees: " << angle(rng) << ") { " << (i % 2 ? "sphere(radius: " + std::to_string(0.5 * sz) + ")"
                                                               : "capsule(radius: " + std::to_string(0.3 * sz) + ", height: " + std::to_string(sz) + ")")
      << " } }\n";
  }
  s << "  }\n}\n";
  const CompiledScene c = checkedParts(s.str(), 32);
  const ir::Node* set = findSet(*c.scene.root);
  ASSERT_TRUE(set);
  const ir::InstanceGrid& g = set->instances->grid;
  ASSERT_FALSE(g.empty());
  int long_lists = 0, longest = 0;
  for (size_t k = size_t(g.dims.x) * g.dims.y * g.dims.z; k < g.count.size(); ++k) {
    long_lists += g.count[k] > ir::kGridListMax;
    longest = std::max(longest, int(g.count[k]));
  }
  EXPECT_GT(long_lists, 0);
  EXPECT_LE(longest, ir::kGridListMaxCrowded);
  // Exact: no hit off the surface. Rays that skim a part within the hit band
  // pass it (the near-miss rule): in so dense a clump 1-2% of the hits, the
  // same as with lists of at most kGridListMax (for boxes: 35 against 36).
  const Verdict v = check(s.str());
  std::printf("[ parts    ] 1,500 spheres and capsules in a dense clump: %d hit pixels, %d off the surface (worst %.3g "
              "footprints), %d with a surface before them, %d missed\n", v.hits, v.off, v.worst, v.early, v.missed);
  EXPECT_GT(v.hits, 500);
  EXPECT_EQ(v.off, 0);
  EXPECT_LE(v.early, v.hits / 25);
  EXPECT_LE(v.missed, 2);
}

// Five kinds of rotated parts of varied sizes: five instance sets in one
// union. Round 4 found up to 2,469 pixels 0.26 off: traversals out of visits
// answered a box distance of 0, taken as a hit.
TEST_F(ManyPartsGpu, HardUnionOfFiveSetsIsExact) {
  if (context_->loop_cap) GTEST_SKIP() << "the driver caps loops: traversals are rationed (docs/large_scenes.md)";
  for (unsigned seed : {1u, 2u}) expectExact("hard union, 5 x 60 parts", mixedParts(5, 60, "union", seed));
}

// A smooth blend of many spheres (one smooth set) and of mixed parts (five
// smooth sets under a smooth union): round 4 drew boxes where spheres
// should be, and 512 mixed parts as one solid box.
TEST_F(ManyPartsGpu, SmoothBlendsAreExact) {
  if (context_->loop_cap) GTEST_SKIP() << "the driver caps loops: traversals are rationed (docs/large_scenes.md)";
  for (double k : {0.02, 0.1, 0.2}) {
    std::ostringstream op;
    op << "union(smooth: " << k << ")";
    expectExact("smooth " + op.str() + ", 300 spheres", mixedParts(1, 300, op.str(), 3));
    expectExact("smooth " + op.str() + ", 5 x 100 parts", mixedParts(5, 100, op.str(), 4));
  }
}

// The same sets under subtract and intersect: a box carved by 200 parts, and
// the parts' union cut by a sphere.
// The pieces above through the kernel: definitions as code beside a mixed set.
TEST_F(ManyPartsGpu, DistinctParametricPartsAreExact) {
  if (context_->loop_cap) GTEST_SKIP() << "the driver caps loops: traversals are rationed (docs/large_scenes.md)";
  expectExact("64 pieces, hard", pieces(64, 0));
  expectExact("64 pieces, smooth 0.05", pieces(64, 0.05));
}

TEST_F(ManyPartsGpu, CarvedAndIntersectedSetsAreExact) {
  if (context_->loop_cap) GTEST_SKIP() << "the driver caps loops: traversals are rationed (docs/large_scenes.md)";
  expectExact("box minus 5 x 40 parts", mixedParts(5, 40, "union", 5, true));
  expectExact("box minus a smooth blend of 5 x 40 parts", mixedParts(5, 40, "union(smooth: 0.1)", 6, true));
  std::string cut = mixedParts(5, 60, "union(smooth: 0.05)", 7);
  cut.replace(cut.find("scene {\n"), 8, "scene {\n  intersect {\n  sphere(radius: 2.2)\n");
  cut.insert(cut.rfind('}'), "}\n");
  expectExact("a sphere intersected with a smooth blend of 5 x 60 parts", cut);
}

// Copies' own materials of every model (metal, glass, emissive, diffuse, a
// colour field),
// which live only in the set's data: the kernel keeps each model's code, and
// the beauty image is the inline code's. Before, the kernel dropped the
// models only copies used (they are on no node): metal copies drew black.
TEST_F(ManyPartsGpu, CopiesOwnMaterialsOfEveryModelAreShaded) {
  std::ostringstream s;
  s << "camera(position: [0, 2, 9], target: [0, 0, 0], fov: 40)\nsun(direction: [0.3, 1, 0.4])\n"
       "let gold = metal(albedo: [0.9, 0.7, 0.3], roughness: 0.2)\nlet clear = glass(ior: 1.5)\n"
       "let lamp = emissive(color: [1, 0.8, 0.6], strength: 3)\nlet clay = diffuse(albedo: [0.7, 0.4, 0.3])\n"
       "let tiles = diffuse(albedo: checker(a: [0.9, 0.9, 0.9], b: [0.1, 0.1, 0.6], size: 0.1))\n"
       "scene {\n  union {\n";
  const char* mats[] = {"gold", "clear", "lamp", "clay", "tiles"};
  // Spheres and rotated boxes: a mixed set of rotations alone, whose records
  // carry template and material in one float.
  for (int i = 0; i < 64; ++i) {
    const std::string m = std::string(", material: ") + mats[(i / 2) % 5] + ")";
    s << "    translate([" << (i % 8) - 3.5 << ", " << (i / 8) * 0.6 - 2.1 << ", " << 0.3 * (i % 3) << "]) { ";
    if (i % 3 == 0)
      s << "rotate(axis: [1, 2, 0.5], degrees: " << 7 * i << ") { box(size: [0.4, 0.3, 0.35]" << m << " }";
    else
      s << "sphere(radius: " << 0.22 + 0.01 * (i % 5) << m;
    s << " }\n";
  }
  s << "  }\n}\n";
  FloatImage images[2];
  for (int threshold : {32, 0}) {
    CompileOptions options;
    options.instancing.threshold = threshold;
    Diagnostics diags;
    const CompiledScene c = compileSource("materials.sdf", s.str(), options, diags);
    ASSERT_TRUE(c.ok) << diags.format();
    EXPECT_EQ(c.emitted.stats.instance_sets, threshold ? 1 : 0);
    if (threshold) EXPECT_NE(c.emitted.glsl.find("int w = int(r1.w);"), std::string::npos);
    for (const char* model : {"SDFC_HAS_METAL", "SDFC_HAS_GLASS", "SDFC_HAS_EMISSIVE", "SDFC_HAS_DIFFUSE"})
      EXPECT_TRUE(c.emitted.stats.features.count(model)) << model << " threshold " << threshold;
    RenderOverrides o;
    o.width = 96;
    o.height = 54;
    o.spp = 16;
    Renderer r(*context_, c);
    images[threshold ? 0 : 1] = r.render(cameraFor(c.scene), renderSettingsFor(c, o)).color;
  }
  // The same paths through the same surfaces: equal up to float rounding.
  double mean[2] = {0, 0}, worst = 0;
  for (size_t i = 0; i < images[0].rgba.size(); ++i) {
    if (i % 4 == 3) continue;
    mean[0] += images[0].rgba[i];
    mean[1] += images[1].rgba[i];
    worst = std::max(worst, double(std::fabs(images[0].rgba[i] - images[1].rgba[i])));
  }
  EXPECT_NEAR(mean[0], mean[1], 0.01 * mean[1]);
  std::printf("[ parts    ] own materials: sums %.1f (set) and %.1f (code), worst channel difference %.3g\n", mean[0],
              mean[1], worst);
}

// `text`'s scene (one shape in `scene { }`) inside `op { ... }`.
std::string wrapScene(const std::string& text, const std::string& op) {
  std::string s = text;
  s.replace(s.find("scene {\n"), 8, "scene {\n  " + op + " {\n");
  s.insert(s.rfind('}'), "}\n");
  return s;
}

// A set under what lowers its field (a round, a shell, a displace, a smooth
// blend with another shape, a morph, and such under a scale or a twist): a bound the set gives
// for parts it does not list (a grid cell's reach, a box of its hierarchy)
// must stay above what is taken off, or the field crosses 0 in empty space.
// Before, these drew 1,111 of 4,825 hit pixels off the surface (up to 8.6
// footprints) under the round, 502 under the shell, 101 under the displace
// and 9 in the blend with a sphere: the cells' reaches were under what the
// nodes above took off.
TEST_F(ManyPartsGpu, OffsetsAboveASetNeverStopOnItsBounds) {
  if (context_->loop_cap) GTEST_SKIP() << "the driver caps loops: traversals are rationed (docs/large_scenes.md)";
  const std::string hard = mixedParts(5, 60, "union", 21), smooth = mixedParts(5, 60, "union(smooth: 0.05)", 22);
  // Rounded parts are skimmed more often: 57 and 43 pixels with inline code.
  expectExact("round 0.1 of 5 x 60 parts", wrapScene(hard, "round(radius: 0.1)"), 50);
  expectExact("round 0.1 of a smooth blend of 5 x 60 parts", wrapScene(smooth, "round(radius: 0.1)"), 50);
  expectExact("shell 0.08 of 5 x 60 parts", wrapScene(hard, "shell(thickness: 0.08)"));
  expectExact("displace 0.05 of 5 x 60 parts", wrapScene(hard, "displace(amplitude: 0.05, scale: 3)"));
  // The parts at half size rounded by 0.05, twice as large: rounded by 0.1.
  expectExact("scale 2 of round 0.05 of scale 0.5 of 5 x 60 parts",
              wrapScene(wrapScene(wrapScene(hard, "scale(0.5)"), "round(radius: 0.05)"), "scale(2)"), 50);
  // Known only after the bottom-up pass: a twist's stretch, and how deep
  // the other shape of a morph goes (the set's grid is built again for them).
  expectExact("round 0.1 of a twist of 5 x 60 parts", wrapScene(wrapScene(hard, "twist(rate: 20)"), "round(radius: 0.1)"),
              50);
  std::string morph = hard;
  morph.replace(morph.find("scene {\n"), 8, "scene {\n  morph(t: 0.4) {\n  sphere(radius: 1.5)\n");
  morph.insert(morph.rfind('}'), "}\n");
  expectExact("a morph 0.4 of a sphere and 5 x 60 parts", morph, 50);  // 8 of 556 as inline code too
  std::string blend = hard;
  blend.replace(blend.find("scene {\n"), 8, "scene {\n  union(smooth: 0.3) {\n  sphere(radius: 0.5)\n");
  blend.insert(blend.rfind('}'), "}\n");
  expectExact("a smooth union 0.3 of a sphere and 5 x 60 parts", blend);
}

// The kernel's distances through the sets' grids against the evaluator's, at
// points inside the parts as well as near and beyond them (overlapping mixed,
// rotated parts in a hard or smooth union, as holes and intersected): exact at the surface,
// and elsewhere a bound on the safe side on either side of it, never farther
// from the surface than the evaluator says (a grid cell's reach bounds the
// parts it does not list; a subtract turns that into a shallower interior),
// so neither a march from outside nor one inside glass passes a surface.
TEST_F(ManyPartsGpu, SetDistancesInsideThePartsAreTheEvaluators) {
  if (context_->loop_cap) GTEST_SKIP() << "the driver caps loops: traversals are rationed (docs/large_scenes.md)";
  const std::vector<std::string> kinds = {"sphere", "box", "capsule", "cylinder", "torus"};
  unsigned seed = 40;
  // A union's interior is the intersected form's; a smooth one's, the smooth holes'.
  for (const char* form : {"holes", "intersect", "smooth holes"})
    for (int n : {250}) {
      CompileOptions options;
      options.emit.with_kernel = false;
      options.produce_spirv = false;
      options.emit.bounding_volumes = false;
      options.camera_frame = false;
      Diagnostics diags;
      // Intersected, the parts only rotate: records of a quaternion (the others hold 3x4 maps).
      const bool scaled = std::string(form) != "intersect";
      const CompiledScene c =
          compileSource("parts.sdf", overlappingParts(kinds, n, form, seed++, scaled), options, diags);
      ASSERT_TRUE(c.ok) << diags.format();
      ASSERT_GE(c.emitted.stats.instance_sets, 1);
      EXPECT_NE(c.emitted.glsl.find(scaled ? "r2 = sd_data[rec + 2]" : "cross(r0.xyz, p)"), std::string::npos) << form;
      const SpirvResult spirv =
          glslToSpirv(test::pointShaderSource(c.emitted), ShaderStage::Fragment, "parts.points.frag");
      ASSERT_TRUE(spirv.ok()) << spirv.log;
      const test::GpuPoints gpu =
          test::runPoints(*context_, spirv.words, glm::vec3(0), glm::vec3(3.5f), 42, 0, c.emitted.scene_data);
      const Evaluator eval(c.scene);
      const double tolerance = 64.0 / 8388608.0 * 8;  // float32 at the scene's scale
      int inside = 0, near = 0, wrong_side = 0, beyond = 0, inexact = 0;
      for (size_t i = 0; i < gpu.points.size(); ++i) {
        const double e = eval.at(dvec3(gpu.points[i])).distance, g = gpu.distances[i];
        inside += e < 0;
        if (std::fabs(e) > tolerance) wrong_side += (g < 0) != (e < 0);
        beyond += std::fabs(g) > std::fabs(e) + tolerance;
        if (std::fabs(e) < 0.003) {
          ++near;
          inexact += std::fabs(g - e) > tolerance;
        }
      }
      std::printf("[ parts    ] %s of %d: %d points inside, %d at the surface\n", form, n, inside, near);
      EXPECT_GT(inside, 100) << form;
      EXPECT_GT(near, 5) << form;
      EXPECT_EQ(wrong_side, 0) << form << " of " << n;
      EXPECT_EQ(beyond, 0) << form << " of " << n;
      EXPECT_EQ(inexact, 0) << form << " of " << n;
    }
}

// The kernel's kDriverCapsLoops is specialised from the driver (prelude.glsl,
// render_pipeline.cpp): only a kernel specialised for a loop cap takes a blend
// list's hierarchy fallback, and where no visits are rationed the two kernels
// draw the same bits.
TEST_F(ManyPartsGpu, LoopCapSpecialisationDropsOnlyTheBlendFallback) {
  CompileOptions options;
  options.emit.bounding_volumes = false;
  Diagnostics diags;
  const CompiledScene c = compileSource("many_parts.sdf", mixedParts(5, 100, "union(smooth: 0.1)", 4), options, diags);
  ASSERT_TRUE(c.ok) << diags.format();
  ASSERT_NE(c.emitted.glsl.find("kDriverCapsLoops && count * (count + 2) >"), std::string::npos);
  const bool driver_caps = context_->loop_cap;
  context_->loop_cap = true;
  Renderer capped(*context_, c);
  context_->loop_cap = false;
  Renderer uncapped(*context_, c);
  context_->loop_cap = driver_caps;
  gpu::FrameParams params = makeFrameParams(cameraFor(c.scene), 64, 36, 0);
  params.view = gpu::kViewDepth;
  params.sample_count = 1;
  auto draw = [&](Renderer& r) {
    FloatImage color, normal_depth, albedo_steps;
    r.renderPass(params, 120.0, color, normal_depth, albedo_steps);
    // Compared as bytes: the same bits, not merely equal floats.
    std::string bytes(reinterpret_cast<const char*>(normal_depth.rgba.data()), normal_depth.rgba.size() * sizeof(float));
    bytes.append(reinterpret_cast<const char*>(albedo_steps.rgba.data()), albedo_steps.rgba.size() * sizeof(float));
    return bytes;
  };
  params.traversal_visits = kUncappedTraversalVisits;
  EXPECT_TRUE(draw(capped) == draw(uncapped)) << "the same lists, the same bits";
  // Eight visits: the capped kernel's lists of 3 or more go to the hierarchy,
  // which runs out of visits (a bound, more steps); the other ignores visits.
  params.traversal_visits = 8;
  EXPECT_FALSE(draw(capped) == draw(uncapped)) << "the specialisation did not reach the driver";
}

}  // namespace
}  // namespace sdfc
