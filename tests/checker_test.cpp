// The checker's diagnostics, pinned: input text -> the exact printed output
// (file:line:column, message, source line, caret), through checkSource, so
// parse, check and analysis all run. Plus robustness: random bytes and deep
// nesting give errors and never crash.
#include <gtest/gtest.h>

#include <random>

#include "driver/compile.h"

namespace sdfc {
namespace {

// The diagnostics point into the compiled scene's source: format while it lives.
std::string diagnosticsFor(const std::string& text) {
  Diagnostics diags;
  const CompiledScene compiled = checkSource("t.sdf", text, {}, diags);
  return diags.format();
}

// On a mismatch, prints the actual output as a C++ literal to paste here.
std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '\n') out += "\\n\"\n\"";
    else if (c == '"' || c == '\\') out += std::string("\\") + c;
    else out += c;
  }
  return out + "\"";
}

struct Pinned {
  const char* input;
  const char* expected;
};

void expectPinned(const std::vector<Pinned>& cases) {
  for (const Pinned& c : cases) {
    const std::string actual = diagnosticsFor(c.input);
    EXPECT_EQ(actual, c.expected) << "input: " << c.input << "\nactual:\n" << quoted(actual);
  }
}

TEST(Checker, NamesAndDefinitions) {
  expectPinned({
      {"scene { sphere(radius: rr) }\nlet r = 1\n",
       "t.sdf:1:24: error: unknown name 'rr'; did you mean 'r'?\n"
       "scene { sphere(radius: rr) }\n"
       "                       ^~\n"
       "t.sdf:2:5: warning: 'r' is never used [-Wunused]\n"
       "let r = 1\n"
       "    ^\n"},
      {"let a = b\nlet b = a\nscene { sphere(radius: a) }\n",
       "t.sdf:2:9: error: 'a' is defined in terms of itself\n"
       "let b = a\n"
       "        ^\n"
       "t.sdf:1:5: note: 'a' is defined here\n"
       "let a = b\n"
       "    ^\n"},
      {"let a = 1\nlet a = 2\nscene { sphere(radius: a) }\n",
       "t.sdf:2:5: error: 'a' is already defined\n"
       "let a = 2\n"
       "    ^\n"
       "t.sdf:1:5: note: previous definition is here\n"
       "let a = 1\n"
       "    ^\n"},
      {"let sphere = 1\nscene { box(size: [1, 1, 1]) }\n",
       "t.sdf:1:5: error: 'sphere' is a built-in name and cannot be redefined\n"
       "let sphere = 1\n"
       "    ^~~~~~\n"},
      {"scene { sphere(radius: 1) }\nscene { sphere(radius: 2) }\n",
       "t.sdf:2:1: error: the file already has a scene\n"
       "scene { sphere(radius: 2) }\n"
       "^~~~~\n"},
      {"scene { sphere(radius: pi / 4) translate(time) { box } }\n",
       "t.sdf:1:50: error: 'box' must be called: 'box(...)'\n"
       "scene { sphere(radius: pi / 4) translate(time) { box } }\n"
       "                                                 ^~~\n"},
      {"scene { sphre(radius: 1) }\n",
       "t.sdf:1:9: error: unknown function 'sphre'; did you mean 'sphere'?\n"
       "scene { sphre(radius: 1) }\n"
       "        ^~~~~\n"},
      // Other tools' spellings, which no edit distance reaches.
      {"scene { smooth_union { sphere(1) } }\n",
       "t.sdf:1:9: error: unknown function 'smooth_union'; sdfc writes this as 'union(smooth: k) { ... }'\n"
       "scene { smooth_union { sphere(1) } }\n"
       "        ^~~~~~~~~~~~\n"},
      {"scene { opSmoothSubtraction { sphere(1) } }\n",
       "t.sdf:1:9: error: unknown function 'opSmoothSubtraction'; sdfc writes this as 'subtract(smooth: k) { ... }'\n"
       "scene { opSmoothSubtraction { sphere(1) } }\n"
       "        ^~~~~~~~~~~~~~~~~~~\n"},
      {"scene { difference { sphere(1) } }\n",
       "t.sdf:1:9: error: unknown function 'difference'; sdfc writes this as 'subtract { ... }'\n"
       "scene { difference { sphere(1) } }\n"
       "        ^~~~~~~~~~\n"},
  });
}

TEST(Checker, ParametersAndTypes) {
  expectPinned({
      {"scene { sphere(radus: 1) }\n",
       "t.sdf:1:16: error: 'sphere' has no parameter 'radus'; did you mean 'radius'?\n"
       "scene { sphere(radus: 1) }\n"
       "               ^~~~~\n"},
      {"scene { rotate(axis: [0, 1, 0], angle: 90) { sphere(1) } }\n",
       "t.sdf:1:33: error: 'rotate' has no parameter 'angle'; did you mean 'degrees'?\n"
       "scene { rotate(axis: [0, 1, 0], angle: 90) { sphere(1) } }\n"
       "                                ^~~~~\n"},
      {"scene { sphere() }\n",
       "t.sdf:1:9: error: 'sphere' needs 'radius'\n"
       "scene { sphere() }\n"
       "        ^~~~~~~~\n"},
      {"scene { sphere(radius: [1, 2, 3]) }\n",
       "t.sdf:1:24: error: 'radius' of 'sphere' must be a number, not a vector\n"
       "scene { sphere(radius: [1, 2, 3]) }\n"
       "                       ^~~~~~~~~\n"},
      {"scene { box(size: 1) }\n",
       ""},
      {"scene { sphere(radius: 1, radius: 2) }\n",
       "t.sdf:1:27: error: 'radius' is given twice\n"
       "scene { sphere(radius: 1, radius: 2) }\n"
       "                          ^~~~~~\n"},
      {"scene { sphere(radius: 1) { box(size: [1, 1, 1]) } }\n",
       "t.sdf:1:9: error: 'sphere' is a primitive and takes no block\n"
       "scene { sphere(radius: 1) { box(size: [1, 1, 1]) } }\n"
       "        ^~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~\n"},
      {"scene { translate([1, 0, 0]) }\n",
       "t.sdf:1:9: error: 'translate' needs a block of shapes: 'translate(...) { ... }'\n"
       "scene { translate([1, 0, 0]) }\n"
       "        ^~~~~~~~~~~~~~~~~~~~\n"},
      {"scene { union { 1 } }\n",
       "t.sdf:1:17: error: 'union' expects shapes in its block, not a number\n"
       "scene { union { 1 } }\n"
       "                ^\n"},
      {"let m = 2\nscene { sphere(radius: 1, material: m) }\n",
       "t.sdf:2:37: error: 'material' must be a material, not a number\n"
       "scene { sphere(radius: 1, material: m) }\n"
       "                                    ^\n"},
      {"scene { sphere(radius: [1, 2] + [1, 2, 3]) }\n",
       "t.sdf:1:24: error: vectors of different sizes (2 and 3)\n"
       "scene { sphere(radius: [1, 2] + [1, 2, 3]) }\n"
       "                       ^~~~~~~~~~~~~~~~~~\n"},
      {"scene { morph(t: 0.5) { sphere(radius: 1) } }\n",
       "t.sdf:1:9: error: 'morph' blends exactly 2 shapes, got 1\n"
       "scene { morph(t: 0.5) { sphere(radius: 1) } }\n"
       "        ^~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~\n"},
      {"scene { rotate(axis: [0, 1, 0], degrees: 30, euler: [1, 2, 3]) { sphere(radius: 1) } }\n",
       "t.sdf:1:9: error: 'rotate' takes either 'axis' and 'degrees' or 'euler', not both\n"
       "scene { rotate(axis: [0, 1, 0], degrees: 30, euler: [1, 2, 3]) { sphere(radius: 1) } }\n"
       "        ^~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~\n"},
      {"scene { rotate(degrees: 30) { sphere(radius: 1) } }\n",
       "t.sdf:1:9: error: 'rotate' needs 'axis' and 'degrees', or 'euler'\n"
       "scene { rotate(degrees: 30) { sphere(radius: 1) } }\n"
       "        ^~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~\n"},
  });
}

TEST(Checker, Values) {
  expectPinned({
      {"scene { sphere(radius: -1) }\n",
       "t.sdf:1:24: error: 'radius' of 'sphere' must be positive, got -1\n"
       "scene { sphere(radius: -1) }\n"
       "                       ^~\n"},
      {"scene { box(size: [1, 0, 1]) }\n",
       "t.sdf:1:19: error: every component of 'size' of 'box' must be positive, got 0\n"
       "scene { box(size: [1, 0, 1]) }\n"
       "                  ^~~~~~~~~\n"},
      {"scene { box(size: [1, 1, 1], rounding: 0.6) }\n",
       "t.sdf:1:9: error: box 'rounding' (0.6) must be at most half the smallest side (0.5)\n"
       "scene { box(size: [1, 1, 1], rounding: 0.6) }\n"
       "        ^~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~\n"},
      {"scene { menger(level: 9) }\n",
       "t.sdf:1:9: error: menger 'level' must be a whole number from 0 to 8 (deeper holes are below float32 marching precision), got 9\n"
       "scene { menger(level: 9) }\n"
       "        ^~~~~~~~~~~~~~~~\n"},
      {"scene { menger(level: 1.5) }\n",
       "t.sdf:1:9: error: menger 'level' must be a whole number from 0 to 8 (deeper holes are below float32 marching precision), got 1.5\n"
       "scene { menger(level: 1.5) }\n"
       "        ^~~~~~~~~~~~~~~~~~\n"},
      {"scene { repeat(cell: [0, 0, 0]) { sphere(radius: 1) } }\n",
       "t.sdf:1:22: error: 'cell' of 'repeat' must be positive along at least one axis\n"
       "scene { repeat(cell: [0, 0, 0]) { sphere(radius: 1) } }\n"
       "                     ^~~~~~~~~\n"},
      {"scene { repeat(cell: [1, 1, 1], count: [20000, 1, 1]) { sphere(radius: 1) } }\n",
       "t.sdf:1:40: error: 'count' of 'repeat' must hold whole numbers from 0 (infinite) to 10000, got 20000\n"
       "scene { repeat(cell: [1, 1, 1], count: [20000, 1, 1]) { sphere(radius: 1) } }\n"
       "                                       ^~~~~~~~~~~~~\n"},
      {"scene { repeat(cell: [1, 1, 1], count: [2.5, 1, 1]) { sphere(radius: 1) } }\n",
       "t.sdf:1:40: error: 'count' of 'repeat' must hold whole numbers from 0 (infinite) to 10000, got 2.5\n"
       "scene { repeat(cell: [1, 1, 1], count: [2.5, 1, 1]) { sphere(radius: 1) } }\n"
       "                                       ^~~~~~~~~~~\n"},
      {"scene { plane(normal: [0, 0, 0]) }\n",
       "t.sdf:1:23: error: 'normal' of 'plane' must not be the zero vector\n"
       "scene { plane(normal: [0, 0, 0]) }\n"
       "                      ^~~~~~~~~\n"},
      {"scene { sphere(radius: 1 / 0) }\n",
       "t.sdf:1:28: error: division by zero\n"
       "scene { sphere(radius: 1 / 0) }\n"
       "                           ^\n"},
      {"scene { sphere(radius: 1e999) }\n",
       "t.sdf:1:24: error: number '1e999' is too large to be finite\n"
       "scene { sphere(radius: 1e999) }\n"
       "                       ^~~~~\n"},
      {"scene { sphere(radius: sqrt(-1)) }\n",
       "t.sdf:1:24: error: 'sqrt' gives a value that is not finite here\n"
       "scene { sphere(radius: sqrt(-1)) }\n"
       "                       ^~~~~~~~\n"},
      {"scene { sphere(radius: 1 + sin(time)) }\n",
       "t.sdf:1:24: warning: 'radius' of 'sphere' may reach 0 over time; it must stay positive [-Wtime-range]\n"
       "scene { sphere(radius: 1 + sin(time)) }\n"
       "                       ^~~~~~~~~~~~~\n"},
      {"scene { menger(level: time) }\n",
       "t.sdf:1:23: error: 'level' of 'menger' must be a constant; it cannot depend on 'time'\n"
       "scene { menger(level: time) }\n"
       "                      ^~~~\n"},
  });
}

TEST(Checker, SettingsAndMaterials) {
  expectPinned({
      {"camera(position: [0, 5, 0], target: [0, 0, 0])\nscene { sphere(radius: 1) }\n",
       "t.sdf:1:1: error: the camera's 'up' is parallel to its view direction\n"
       "camera(position: [0, 5, 0], target: [0, 0, 0])\n"
       "^~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~\n"},
      {"camera(position: [0, 0, 0], target: [0, 0, 0])\nscene { sphere(radius: 1) }\n",
       "t.sdf:1:1: error: the camera's 'target' equals its 'position'\n"
       "camera(position: [0, 0, 0], target: [0, 0, 0])\n"
       "^~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~\n"},
      {"camera(fov: 200)\nscene { sphere(radius: 1) }\n",
       "t.sdf:1:13: error: 'fov' must be between 0 and 180 degrees, got 200\n"
       "camera(fov: 200)\n"
       "            ^~~\n"},
      {"render(size: [0, 10])\nscene { sphere(radius: 1) }\n",
       "t.sdf:1:14: error: 'size' must be whole numbers from 1 to 16384\n"
       "render(size: [0, 10])\n"
       "             ^~~~~~~\n"},
      {"render(spp: 1.5)\nscene { sphere(radius: 1) }\n",
       "t.sdf:1:13: error: 'spp' must be a whole number from 1 to 1048576, got 1.5\n"
       "render(spp: 1.5)\n"
       "            ^~~\n"},
      {"render(spp: 4)\nrender(spp: 8)\nscene { sphere(radius: 1) }\n",
       "t.sdf:2:1: warning: 'render' is set again; the last one wins [-Wsetting-again]\n"
       "render(spp: 8)\n"
       "^~~~~~\n"},
      {"scene { camera(fov: 30) }\n",
       "t.sdf:1:9: error: 'camera' is a setting; write it as a statement on its own line\n"
       "scene { camera(fov: 30) }\n"
       "        ^~~~~~\n"},
      {"sky(color: [1, 1, 1], top: [1, 1, 1])\nscene { sphere(radius: 1) }\n",
       "t.sdf:1:1: error: 'sky' takes 'color', or 'top' and 'bottom'\n"
       "sky(color: [1, 1, 1], top: [1, 1, 1])\n"
       "^~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~~\n"},
      {"sun(angle: 60)\nscene { sphere(radius: 1) }\n",
       "t.sdf:1:12: error: 'angle' of 'sun' must be at most 45 degrees\n"
       "sun(angle: 60)\n"
       "           ^~\n"},
      {"let g = glass(ior: 9)\nscene { sphere(radius: 1, material: g) }\n",
       "t.sdf:1:20: error: 'ior' of 'glass' must be in [1, 4], got 9\n"
       "let g = glass(ior: 9)\n"
       "                   ^\n"},
      {"let m = metal(roughness: 2)\nscene { sphere(radius: 1, material: m) }\n",
       "t.sdf:1:26: error: 'roughness' of 'metal' must be in [0, 1], got 2\n"
       "let m = metal(roughness: 2)\n"
       "                         ^\n"},
      {"let m = diffuse(albedo: [-1, 0, 0])\nscene { sphere(radius: 1, material: m) }\n",
       "t.sdf:1:25: error: every component of 'albedo' of 'diffuse' must not be negative, got -1\n"
       "let m = diffuse(albedo: [-1, 0, 0])\n"
       "                        ^~~~~~~~~~\n"},
      {"let m = diffuse()\nscene { sphere(radius: 1, material: m, material: m) }\n",
       "t.sdf:2:40: error: 'material' is given twice\n"
       "scene { sphere(radius: 1, material: m, material: m) }\n"
       "                                       ^~~~~~~~\n"},
      {"camera(fov: 30)\n",
       "t.sdf:2:1: error: the file has no 'scene { ... }'\n"
       "\n"
       "^\n"},
      {"scene { }\n",
       "t.sdf:1:1: error: the scene is empty\n"
       "scene { }\n"
       "^~~~~~~~~\n"},
  });
}

TEST(Checker, Warnings) {
  expectPinned({
      {"let unused = 3\nscene { sphere(radius: 1) }\n",
       "t.sdf:1:5: warning: 'unused' is never used [-Wunused]\n"
       "let unused = 3\n"
       "    ^~~~~~\n"},
      {"let m = diffuse()\nlet n = diffuse()\nscene { sphere(radius: 1, material: n) }\n",
       "t.sdf:1:9: warning: material 'm' is never used by a shape [-Wunused]\n"
       "let m = diffuse()\n"
       "        ^~~~~~~~~\n"},
      {"scene { scale([1, 2, 1]) { sphere(radius: 1) } }\n",
       "t.sdf:1:9: warning: non-uniform 'scale' gives a distance bound, not an exact distance (marching takes smaller steps) [-Wbound]\n"
       "scene { scale([1, 2, 1]) { sphere(radius: 1) } }\n"
       "        ^~~~~\n"},
      {"scene { union(smooth: 0.2) { sphere(radius: 1) box(size: [1, 1, 1]) } }\n",
       "t.sdf:1:9: warning: smooth 'union' gives a distance bound, not an exact distance (marching takes smaller steps near it) [-Wbound]\n"
       "scene { union(smooth: 0.2) { sphere(radius: 1) box(size: [1, 1, 1]) } }\n"
       "        ^~~~~\n"},
      {"scene { morph(t: 0.5) { sphere(radius: 1) box(size: [1, 1, 1]) } }\n",
       "t.sdf:1:9: warning: 'morph' gives a distance bound, not an exact distance [-Wbound]\n"
       "scene { morph(t: 0.5) { sphere(radius: 1) box(size: [1, 1, 1]) } }\n"
       "        ^~~~~\n"},
      {"scene { subtract { sphere(radius: 1) } }\n",
       "t.sdf:1:9: warning: 'subtract' with one shape subtracts nothing [-Wsubtract-nothing]\n"
       "scene { subtract { sphere(radius: 1) } }\n"
       "        ^~~~~~~~~~~~~~~~~~~~~~~~~~~~~~\n"},
      {"scene { torus(major: 0.2, minor: 0.5) }\n",
       "t.sdf:1:9: warning: torus 'minor' > 'major' makes a spindle torus; its distance is only a bound near the axis [-Wbound]\n"
       "scene { torus(major: 0.2, minor: 0.5) }\n"
       "        ^~~~~~~~~~~~~~~~~~~~~~~~~~~~~\n"},
  });
}

TEST(Checker, ValidSceneHasNoDiagnostics) {
  EXPECT_EQ(diagnosticsFor("let r = 0.5\nlet m = diffuse(albedo: [0.8, 0.8, 0.8])\n"
                           "scene { translate([0, r, 0]) { sphere(radius: r, material: m) } }\n"),
            "");
}

TEST(Checker, RandomBytesGiveErrorsNeverACrash) {
  std::mt19937 rng(1234);
  const std::string alphabet = "scene{}()[]:,.+-*/ 0123456789e\nletsphereboxrepeatrotatetime#\"\\";
  for (int round = 0; round < 2000; ++round) {
    std::string text;
    const int n = rng() % 200;
    for (int i = 0; i < n; ++i)
      text += round % 2 ? static_cast<char>(rng() % 256) : alphabet[rng() % alphabet.size()];
    Diagnostics diags;
    const CompiledScene out = checkSource("t.sdf", text, {}, diags);
    EXPECT_TRUE(diags.hasErrors() || out.ok) << quoted(text);
    EXPECT_FALSE(diags.format().empty() && !out.ok) << quoted(text);
  }
}

TEST(Checker, DeepNestingGivesErrorsNeverACrash) {
  const std::string parens = "scene { sphere(radius: " + std::string(100000, '(') + "1" +
                             std::string(100000, ')') + ") }\n";
  EXPECT_NE(diagnosticsFor(parens).find("error:"), std::string::npos);
  std::string blocks = "scene { ";
  for (int i = 0; i < 50000; ++i) blocks += "union { ";
  blocks += "sphere(radius: 1)";
  for (int i = 0; i < 50000; ++i) blocks += " }";
  blocks += " }\n";
  EXPECT_NE(diagnosticsFor(blocks).find("error:"), std::string::npos);
}

// A chain of ~20000 definitions once overflowed the stack in
// Checker::resolve; it is now an error.
TEST(Checker, LongDefinitionChainGivesAnErrorNotACrash) {
  std::string chain = "let a0 = 1\n";
  for (int i = 1; i < 20000; ++i) chain += "let a" + std::to_string(i) + " = a" + std::to_string(i - 1) + " + 1\n";
  chain += "scene { sphere(radius: a19999) }\n";
  Diagnostics diags;
  const CompiledScene compiled = checkSource("t.sdf", chain, {}, diags);
  EXPECT_NE(diags.format().find("definitions refer to each other more than 200 levels deep"),
            std::string::npos);
  // One error and nothing else: the definitions the chain never reached are
  // not "never used" (a chain 5,000 deep gave 4,799 such warnings).
  EXPECT_EQ(diags.errorCount(), 1);
  EXPECT_EQ(diags.format(false, 0).find("never used"), std::string::npos);
}

// Definitions are all checked before any is called unused: one checked later
// uses an earlier one ('a' was "never used" although 'b' uses it).
TEST(Checker, AnUnusedDefinitionsUsesAreUses) {
  expectPinned({{"let a = 1\nlet b = a\nscene { sphere(radius: 1) }\n",
                 "t.sdf:2:5: warning: 'b' is never used [-Wunused]\n"
                 "let b = a\n"
                 "    ^\n"}});
}

// Definitions that double (fK uses fK-1 twice) checked in 0.02 s with their
// values shared, then render took 4.6 GB at 17 levels and crashed at 19, and
// compile and eval took exponential time. The checker bounds the scene as
// written out, with its own error at the call, so a scene that checks renders.
std::string doubling(int levels, bool parametric) {
  std::string text = parametric ? "let f0(x) = sphere(radius: x)\n" : "let f0 = sphere(radius: 1)\n";
  for (int k = 1; k <= levels; ++k) {
    const std::string prev = "f" + std::to_string(k - 1) + (parametric ? "(x)" : "");
    text += "let f" + std::to_string(k) + (parametric ? "(x)" : "") + " = union { " + prev + " " + prev + " }\n";
  }
  return text + "scene { sphere(radius: 1) f" + std::to_string(levels) + (parametric ? "(1)" : "") + " }\n";
}

TEST(Checker, DefinitionsThatDoubleAreBoundedWrittenOut) {
  for (bool parametric : {true, false}) {
    // 2^14 - 1 nodes and the other sphere: kMaxExpandedNodes (16384) exactly.
    EXPECT_EQ(diagnosticsFor(doubling(13, parametric)), "") << parametric;
    const std::string over = diagnosticsFor(doubling(14, parametric));
    // Counted once copies that become data are known: at the shape that grows (f14's body).
    EXPECT_NE(over.find(std::string("t.sdf:15:") + (parametric ? "14" : "11") +
                        ": error: the scene grows to more than 16384 shapes and operations here"),
              std::string::npos) << quoted(over);
    const std::string far = diagnosticsFor(doubling(60, parametric));  // the count saturates, no overflow
    EXPECT_NE(far.find("error: the scene grows to more than 16384"), std::string::npos) << quoted(far);
  }
}

}  // namespace
}  // namespace sdfc
