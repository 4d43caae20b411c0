// Parametric definitions (`let tower(height, radius: 1) = ...`): a call is
// the shape written out (same IR, same distances in the float64 evaluator),
// equal calls share one specialised function, and each mistake gives its
// diagnostic, pinned as printed. The GPU side is in gpu_equivalence_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <random>
#include <sstream>
#include <regex>
#include <set>

#include "driver/compile.h"
#include "eval/evaluator.h"

namespace sdfc {
namespace {

using glm::dvec3;

std::string diagnosticsFor(const std::string& text) {
  Diagnostics diags;
  const CompiledScene compiled = checkSource("t.sdf", text, {}, diags);
  return diags.format();
}

std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '\n') out += "\\n\"\n\"";
    else if (c == '"' || c == '\\') out += std::string("\\") + c;
    else out += c;
  }
  return out + "\"";
}

void expectPinned(const std::string& input, const std::string& expected) {
  const std::string actual = diagnosticsFor(input);
  EXPECT_EQ(actual, expected) << "input: " << input << "\nactual:\n" << quoted(actual);
}

CompiledScene checked(const std::string& text) {
  Diagnostics diags;
  CompiledScene c = checkSource("t.sdf", text, {}, diags);
  EXPECT_FALSE(diags.hasErrors()) << diags.format();
  return c;
}

// The two scenes' distances and materials agree at random points and times.
void expectSameField(const std::string& parametric, const std::string& written, double time = 0.7) {
  const CompiledScene a = checked(parametric), b = checked(written);
  ASSERT_TRUE(a.scene.root && b.scene.root);
  const Evaluator ea(a.scene, time), eb(b.scene, time);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-12, 12);
  for (int i = 0; i < 3000; ++i) {
    const dvec3 p(u(rng), u(rng) * 0.5 + 3, u(rng));
    const EvalResult ra = ea.at(p), rb = eb.at(p);
    ASSERT_NEAR(ra.distance, rb.distance, 1e-12) << "at " << p.x << " " << p.y << " " << p.z;
    ASSERT_EQ(ra.material, rb.material);
  }
}

TEST(Parametric, CallEqualsTheShapeWrittenOut) {
  // The issue's example: positional and named arguments, a default.
  expectSameField(R"(
let tower(height, radius: 1) = union {
  cylinder(radius: radius, height: height)
  translate([0, height / 2, 0]) { cone(radius: radius * 1.2, height: 2) }
}
scene { tower(5) translate([6, 0, 0]) { tower(7, radius: 1.3) } }
)",
                  R"(
scene {
  union { cylinder(radius: 1, height: 5) translate([0, 2.5, 0]) { cone(radius: 1.2, height: 2) } }
  translate([6, 0, 0]) { union { cylinder(radius: 1.3, height: 7) translate([0, 3.5, 0]) { cone(radius: 1.56, height: 2) } } }
}
)");
  // Vectors, shapes and materials as parameters; a default that uses an
  // earlier parameter; arguments that depend on time.
  expectSameField(R"(
let red = diffuse(albedo: [0.8, 0.1, 0.1])
let blue = diffuse(albedo: [0.1, 0.1, 0.8])
let placed(at, s, m: red, lift: at.y + 1) = translate([at.x, lift, at.z]) { union(material: m) { s } }
scene {
  placed([1, 0, 2], sphere(radius: 0.5))
  placed([-3, 1, 0], box(size: [1, 2, 1]), m: blue)
  placed(at: [0, sin(time), -4], s: torus(major: 1, minor: 0.2), lift: 2 + time)
}
)",
                  R"(
let red = diffuse(albedo: [0.8, 0.1, 0.1])
let blue = diffuse(albedo: [0.1, 0.1, 0.8])
scene {
  translate([1, 1, 2]) { union(material: red) { sphere(radius: 0.5) } }
  translate([-3, 2, 0]) { union(material: blue) { box(size: [1, 2, 1]) } }
  translate([0, 2 + time, -4]) { union(material: red) { torus(major: 1, minor: 0.2) } }
}
)");
  // A number-valued definition, and definitions calling definitions.
  expectSameField(R"(
let half(x) = x / 2
let post(h) = translate([0, half(h), 0]) { cylinder(radius: 0.2, height: h) }
let pair(h, gap: 1) = union { translate([-gap, 0, 0]) { post(h) } translate([gap, 0, 0]) { post(h + 1) } }
scene { pair(3) translate([0, 0, 4]) { pair(2, gap: 2) } }
)",
                  R"(
scene {
  union { translate([-1, 0, 0]) { translate([0, 1.5, 0]) { cylinder(radius: 0.2, height: 3) } }
          translate([1, 0, 0]) { translate([0, 2, 0]) { cylinder(radius: 0.2, height: 4) } } }
  translate([0, 0, 4]) {
    union { translate([-2, 0, 0]) { translate([0, 1, 0]) { cylinder(radius: 0.2, height: 2) } }
            translate([2, 0, 0]) { translate([0, 1.5, 0]) { cylinder(radius: 0.2, height: 3) } } }
  }
}
)");
}

// After every pass (fusion, bounds, Lipschitz, instancing) the IR of a call
// is the IR of the same shape bound with a plain `let`.
TEST(Parametric, SameIrAsANamedShape) {
  const std::string copies = [] {
    std::string s;
    for (int i = 0; i < 40; ++i)
      s += "translate([" + std::to_string(i % 8 * 3) + ", 0, " + std::to_string(i / 8 * 3) + "]) { PART }\n";
    return s;
  }();
  auto with = [&](const std::string& part) { return std::regex_replace(copies, std::regex("PART"), part); };
  const CompiledScene a = checked("let part(r, h: 2) = union { sphere(radius: r) translate([0, h, 0]) { box(size: [r, r, r]) } }\n"
                                  "scene { union {\n" + with("part(0.5)") + "} }\n");
  const CompiledScene b = checked("let part = union { sphere(radius: 0.5) translate([0, 2, 0]) { box(size: [0.5, 0.5, 0.5]) } }\n"
                                  "scene { union {\n" + with("part") + "} }\n");
  ASSERT_TRUE(a.scene.root && b.scene.root);
  const std::string da = ir::dump(a.scene), db = ir::dump(b.scene);
  EXPECT_EQ(da, db);
  EXPECT_NE(da.find("instances"), std::string::npos) << "40 copies of one part become data:\n" << da;
}

// A body that is one primitive stays inline, as written out: 40 calls with
// 40 different heights become one set of copies with per-copy parameters.
TEST(Parametric, PrimitiveBodiesGroupLikeWrittenPrimitives) {
  std::string calls, written;
  for (int i = 0; i < 40; ++i) {
    const std::string at = "translate([" + std::to_string(i % 8 * 2) + ", 0, " + std::to_string(i / 8 * 2) + "]) ";
    calls += at + "{ rod(" + std::to_string(1 + i % 5) + ") }\n";
    written += at + "{ cylinder(radius: 0.2, height: " + std::to_string(1 + i % 5) + ") }\n";
  }
  const CompiledScene a = checked("let rod(h) = cylinder(radius: 0.2, height: h)\nscene { union {\n" + calls + "} }\n");
  const CompiledScene b = checked("scene { union {\n" + written + "} }\n");
  ASSERT_TRUE(a.scene.root && b.scene.root);
  // The same but for the source lines the nodes come from.
  const std::regex line("# line \\d+");
  const std::string da = std::regex_replace(ir::dump(a.scene), line, "");
  EXPECT_EQ(da, std::regex_replace(ir::dump(b.scene), line, ""));
  EXPECT_NE(da.find("instances"), std::string::npos) << da;
}

int functionsNamed(const std::string& glsl, const std::string& prefix) {
  std::set<std::string> names;
  const std::regex def("\\nfloat (" + prefix + "\\w*)\\(vec3 p\\)");
  for (auto it = std::sregex_iterator(glsl.begin(), glsl.end(), def); it != std::sregex_iterator(); ++it)
    names.insert((*it)[1]);
  return static_cast<int>(names.size());
}

// The issue's target: 200 calls with 20 distinct argument sets emit 20
// functions, the arguments folded in as constants.
TEST(Parametric, EqualCallsShareOneSpecialisation) {
  std::string text = "let part(h, r: 0.3) = union { cylinder(radius: r, height: h) translate([0, h / 2, 0]) { sphere(radius: r * 2) } }\n"
                     "scene {\n";
  for (int i = 0; i < 200; ++i) {
    const int set = i % 20;
    text += "  translate([" + std::to_string(i % 15 * 2) + ", 0, " + std::to_string(i / 15 * 2 + (i % 3) * 0.3) + "]) { part(" +
            std::to_string(1 + set / 4) + ", r: " + std::to_string(0.1 + 0.05 * (set % 4)) + ") }\n";
  }
  text += "}\n";
  Diagnostics diags;
  CompileOptions options;
  options.produce_spirv = false;
  options.instancing.threshold = 0;  // keep every call as code: count the functions
  const CompiledScene c = compileSource("t.sdf", text, options, diags);
  ASSERT_FALSE(diags.hasErrors()) << diags.format();
  EXPECT_EQ(functionsNamed(c.emitted.glsl, "sd_part"), 20) << c.emitted.glsl.substr(0, 4000);
  // Constants are folded into each specialisation: no parameters at run time.
  EXPECT_EQ(c.emitted.glsl.find("float sd_part(vec3 p, "), std::string::npos);
}

std::string readExample(const std::string& name) {
  std::ifstream in(std::string(SDFC_SOURCE_DIR) + "/examples/" + name, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The issue's target: the castle with parametric towers is the castle (the
// same field and materials at every point), in no more GLSL lines.
TEST(Parametric, CastleWithParametricTowersIsTheCastle) {
  const CompiledScene a = checked(readExample("castle_parametric.sdf")), b = checked(readExample("castle.sdf"));
  ASSERT_TRUE(a.scene.root && b.scene.root);
  const Evaluator ea(a.scene), eb(b.scene);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-9, 9);
  for (int i = 0; i < 20000; ++i) {
    const dvec3 p(u(rng), u(rng) * 0.5 + 4, u(rng));
    const EvalResult ra = ea.at(p), rb = eb.at(p);
    ASSERT_NEAR(ra.distance, rb.distance, 1e-12) << "at " << p.x << " " << p.y << " " << p.z;
    ASSERT_EQ(ra.material < 0, rb.material < 0);
    if (ra.material >= 0) {
      const ir::Material &ma = a.scene.materials[ra.material], &mb = b.scene.materials[rb.material];
      ASSERT_EQ(ma.model, mb.model);
      ASSERT_EQ(ma.albedo.value(), mb.albedo.value());
    }
  }
  auto lines = [](const std::string& name) {
    Diagnostics diags;
    CompileOptions options;
    options.produce_spirv = false;
    const CompiledScene c = compileSource("examples/" + name, readExample(name), options, diags);
    return std::count(c.emitted.glsl.begin(), c.emitted.glsl.end(), '\n');
  };
  EXPECT_LE(lines("castle_parametric.sdf"), lines("castle.sdf"));
}

TEST(Parametric, Diagnostics) {
  const std::string post = "let post(h, r: 0.2) = cylinder(radius: r, height: h)\n";
  // Wrong argument type: at the argument, with a note at the use.
  expectPinned(post + "scene { post(sphere(radius: 1)) }\n", "t.sdf:2:14: error: 'h' of 'post' must be a number, not a shape\n"
                "scene { post(sphere(radius: 1)) }\n"
                "             ^~~~~~~~~~~~~~~~~\n"
                "t.sdf:1:51: note: 'post' uses 'h' as a number here\n"
                "let post(h, r: 0.2) = cylinder(radius: r, height: h)\n"
                "                                                  ^\n");
  // Missing argument.
  expectPinned(post + "scene { post(r: 1) }\n", "t.sdf:2:9: error: 'post' needs 'h'\n"
                "scene { post(r: 1) }\n"
                "        ^~~~~~~~~~\n"
                "t.sdf:1:10: note: 'h' has no default\n"
                "let post(h, r: 0.2) = cylinder(radius: r, height: h)\n"
                "         ^\n");
  // Unknown parameter.
  expectPinned(post + "scene { post(1, rr: 1) }\n", "t.sdf:2:17: error: 'post' has no parameter 'rr'; did you mean 'r'?\n"
                "scene { post(1, rr: 1) }\n"
                "                ^~\n"
                "t.sdf:1:5: note: 'post' is defined here\n"
                "let post(h, r: 0.2) = cylinder(radius: r, height: h)\n"
                "    ^~~~\n");
  // Too many positional arguments.
  expectPinned(post + "scene { post(1, 2, 3) }\n", "t.sdf:2:20: error: 'post' takes at most 2 positional arguments\n"
                "scene { post(1, 2, 3) }\n"
                "                   ^\n"
                "t.sdf:1:5: note: 'post' is defined here\n"
                "let post(h, r: 0.2) = cylinder(radius: r, height: h)\n"
                "    ^~~~\n");
  // A mistake inside the body is reported at the call.
  expectPinned(post + "scene { post(-1) }\n", "t.sdf:2:9: error: in this call of 'post': 'height' of 'cylinder' must be positive, got -1\n"
                "scene { post(-1) }\n"
                "        ^~~~~~~~\n"
                "t.sdf:1:51: note: here, in the definition of 'post'\n"
                "let post(h, r: 0.2) = cylinder(radius: r, height: h)\n"
                "                                                  ^\n");
  // Used without a call; called though it has no parameters.
  expectPinned(post + "let ball = sphere(radius: 1)\nscene { post ball(1) }\n", "t.sdf:3:9: error: 'post' has parameters; call it: 'post(...)'\n"
                "scene { post ball(1) }\n"
                "        ^~~~\n"
                "t.sdf:1:5: note: 'post' is defined here\n"
                "let post(h, r: 0.2) = cylinder(radius: r, height: h)\n"
                "    ^~~~\n"
                "t.sdf:3:14: error: 'ball' has no parameters; use it without '(...)'\n"
                "scene { post ball(1) }\n"
                "             ^~~~\n"
                "t.sdf:2:5: note: 'ball' is defined here\n"
                "let ball = sphere(radius: 1)\n"
                "    ^~~~\n");
  // Recursion, direct and through another definition.
  expectPinned("let f(n) = union { f(n - 1) }\nscene { f(3) }\n", "t.sdf:1:20: error: 'f' calls itself ('f' -> 'f'); recursion is not allowed, nothing could end it\n"
                "let f(n) = union { f(n - 1) }\n"
                "                   ^\n"
                "t.sdf:1:5: note: 'f' is defined here\n"
                "let f(n) = union { f(n - 1) }\n"
                "    ^\n");
  expectPinned("let a(n) = union { b(n) }\nlet b(n) = translate([n, 0, 0]) { a(n) }\nscene { a(1) }\n", "t.sdf:2:35: error: 'a' calls itself ('a' -> 'b' -> 'a'); recursion is not allowed, nothing could end it\n"
                "let b(n) = translate([n, 0, 0]) { a(n) }\n"
                "                                  ^\n"
                "t.sdf:1:20: note: 'b' is called here\n"
                "let a(n) = union { b(n) }\n"
                "                   ^~~~\n"
                "t.sdf:1:5: note: 'a' is defined here\n"
                "let a(n) = union { b(n) }\n"
                "    ^\n");
  // Parameter names: built-ins and duplicates.
  expectPinned("let f(sphere, x, x) = box(size: [1, 1, 1])\nscene { f(1, 2, 3) }\n", "t.sdf:1:7: error: 'sphere' is a built-in name and cannot be a parameter\n"
                "let f(sphere, x, x) = box(size: [1, 1, 1])\n"
                "      ^~~~~~\n"
                "t.sdf:1:18: error: 'f' has two parameters named 'x'\n"
                "let f(sphere, x, x) = box(size: [1, 1, 1])\n"
                "                 ^\n");
  // Never used.
  expectPinned(post + "scene { sphere(radius: 1) }\n", "t.sdf:1:5: warning: 'post' is never used [-Wunused]\n"
                "let post(h, r: 0.2) = cylinder(radius: r, height: h)\n"
                "    ^~~~\n");
}

}  // namespace
}  // namespace sdfc
