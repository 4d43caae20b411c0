// `import "parts.sdf"` and `import "parts.sdf" as parts`: definitions from
// another file, relative to the importing one (here in a directory whose
// name has a space), and each mistake's diagnostic pinned as printed, with
// the directory written as DIR.
#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>
#include <regex>

#include "driver/compile.h"
#include "eval/evaluator.h"

namespace sdfc {
namespace {

namespace fs = std::filesystem;

class Imports : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("sdfc imports " + std::to_string(getpid()) + " " +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  void write(const std::string& name, const std::string& text) {
    fs::create_directories((dir_ / name).parent_path());
    std::ofstream(dir_ / name, std::ios::binary) << text;
  }
  // Checks `name`; the diagnostics with the directory as DIR.
  std::string diagnosticsOf(const std::string& name) {
    Diagnostics diags;
    CompileOptions options;
    options.produce_spirv = false;
    const CompiledScene c = compileFile((dir_ / name).string(), options, diags);
    std::string text = diags.format();
    const std::string prefix = dir_.string() + "/";
    for (size_t at; (at = text.find(prefix)) != std::string::npos;) text.replace(at, prefix.size(), "DIR/");
    return text;
  }
  void expectDiagnostics(const std::string& name, const std::string& expected) {
    const std::string actual = diagnosticsOf(name);
    std::string q = "\"";
    for (char c : actual) {
      if (c == '\n') q += "\\n\"\n\"";
      else if (c == '"' || c == '\\') q += std::string("\\") + c;
      else q += c;
    }
    EXPECT_EQ(actual, expected) << name << "\nactual:\n" << q << "\"";
  }
  CompiledScene compiled(const std::string& name) {
    Diagnostics diags;
    CompiledScene c = compileFile((dir_ / name).string(), {}, diags);
    EXPECT_FALSE(diags.hasErrors()) << diags.format();
    return c;
  }

  fs::path dir_;
};

constexpr const char* kParts =
    "// parts\n"
    "let stone = diffuse(albedo: [0.7, 0.68, 0.6])\n"
    "let base(r) = cylinder(radius: r, height: 0.4, material: stone)\n"
    "let tower(height, radius: 1) = union { base(radius * 1.2) translate([0, height / 2, 0]) { cylinder(radius: radius, height: height) } }\n";

TEST_F(Imports, ImportedDefinitionsEqualTheShapeWrittenHere) {
  write("lib/parts.sdf", kParts);
  write("plain.sdf", "import \"lib/parts.sdf\"\nscene { tower(3) translate([4, 0, 0]) { tower(2, radius: 0.5) } }\n");
  write("qualified.sdf", "import \"lib/parts.sdf\" as parts\n"
                         "scene { parts.tower(3) translate([4, 0, 0]) { parts.tower(2, radius: 0.5) }\n"
                         "  translate([0, 0, 4]) { sphere(radius: 0.5, material: parts.stone) } }\n");
  write("written.sdf", std::string(kParts) +
                           "scene { tower(3) translate([4, 0, 0]) { tower(2, radius: 0.5) }\n"
                           "  translate([0, 0, 4]) { sphere(radius: 0.5, material: stone) } }\n");
  const CompiledScene plain = compiled("plain.sdf"), qualified = compiled("qualified.sdf"),
                      written = compiled("written.sdf");
  ASSERT_TRUE(plain.ok && qualified.ok && written.ok);
  EXPECT_EQ(qualified.scene.imported_sources.size(), 1u);
  const Evaluator a(plain.scene), b(qualified.scene), c(written.scene);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-6, 6);
  for (int i = 0; i < 2000; ++i) {
    const glm::dvec3 p(u(rng), u(rng), u(rng));
    ASSERT_EQ(b.distance(p), c.distance(p));
    if (p.z < 1) {  // far from the sphere only the written scene has
      ASSERT_EQ(a.distance(p), c.distance(p));
    }
  }
  // Compiled to SPIR-V like any scene.
  EXPECT_FALSE(qualified.spirv.empty());
}

TEST_F(Imports, NestedImportsAndOneFileTwice) {
  write("parts.sdf", kParts);
  write("castle parts.sdf", "import \"parts.sdf\"\nlet keep(h) = tower(h, radius: 2)\n");
  write("walls.sdf", "import \"parts.sdf\"\nlet wall = box(size: [4, 1, 0.5], material: stone)\n");
  // parts.sdf reaches main twice (through both), into the same names: read once.
  write("main.sdf", "import \"castle parts.sdf\"\nimport \"walls.sdf\"\nimport \"walls.sdf\" as w\n"
                    "scene { keep(3) wall translate([0, 0, 3]) { w.wall } tower(1) }\n");
  expectDiagnostics("main.sdf", "");
}

TEST_F(Imports, Diagnostics) {
  write("parts.sdf", kParts);
  // A missing file.
  write("missing.sdf", "import \"nowhere.sdf\"\nscene { sphere(radius: 1) }\n");
  expectDiagnostics("missing.sdf", "DIR/missing.sdf:1:8: error: cannot read 'DIR/nowhere.sdf' (imports are relative to the importing file)\n"
                "import \"nowhere.sdf\"\n"
                "       ^~~~~~~~~~~~~\n");
  // A cycle, shown as its chain.
  write("a.sdf", "import \"b.sdf\"\nlet a = sphere(radius: 1)\n");
  write("b.sdf", "import \"a.sdf\"\nlet b = sphere(radius: 1)\n");
  write("cycle.sdf", "import \"a.sdf\"\nscene { a }\n");
  expectDiagnostics("cycle.sdf", "DIR/b.sdf:1:8: error: import cycle: 'DIR/cycle.sdf' -> 'DIR/a.sdf' -> 'DIR/b.sdf' -> 'DIR/a.sdf'\n"
                "import \"a.sdf\"\n"
                "       ^~~~~~~\n"
                "DIR/cycle.sdf:1:8: note: 'DIR/a.sdf' is imported here\n"
                "import \"a.sdf\"\n"
                "       ^~~~~~~\n"
                "DIR/a.sdf:1:8: note: 'DIR/b.sdf' is imported here\n"
                "import \"b.sdf\"\n"
                "       ^~~~~~~\n");
  // A clash: an import and a definition of this file; two imports.
  write("clash.sdf", "import \"parts.sdf\"\nlet stone = diffuse(albedo: [1, 0, 0])\nscene { tower(1) }\n");
  expectDiagnostics("clash.sdf", "DIR/clash.sdf:1:8: error: this import brings in 'stone', which is already defined\n"
                "import \"parts.sdf\"\n"
                "       ^~~~~~~~~~~\n"
                "DIR/parts.sdf:2:5: note: 'stone' from 'DIR/parts.sdf', imported at DIR/clash.sdf:1:8 is defined here\n"
                "let stone = diffuse(albedo: [0.7, 0.68, 0.6])\n"
                "    ^~~~~\n"
                "DIR/clash.sdf:2:5: note: 'stone' is defined here\n"
                "let stone = diffuse(albedo: [1, 0, 0])\n"
                "    ^~~~~\n");  // this 'stone' is used: the tower's shapes without one take it
  write("more.sdf", "let tower = sphere(radius: 1)\n");
  write("clash2.sdf", "import \"parts.sdf\"\nimport \"more.sdf\"\nscene { tower(1) }\n");
  expectDiagnostics("clash2.sdf", "DIR/clash2.sdf:2:8: error: this import brings in 'tower', which is already defined\n"
                "import \"more.sdf\"\n"
                "       ^~~~~~~~~~\n"
                "DIR/more.sdf:1:5: note: 'tower' from 'DIR/more.sdf', imported at DIR/clash2.sdf:2:8 is defined here\n"
                "let tower = sphere(radius: 1)\n"
                "    ^~~~~\n"
                "DIR/parts.sdf:4:5: note: 'tower' from 'DIR/parts.sdf', imported at DIR/clash2.sdf:1:8 is defined here\n"
                "let tower(height, radius: 1) = union { base(radius * 1.2) translate([0, height / 2, 0]) { cylinder(radius: radius, height: height) } }\n"
                "    ^~~~~\n");
  // An imported file holds definitions only.
  write("scene.sdf", "let s = sphere(radius: 1)\nscene { s }\n");
  write("imports_scene.sdf", "import \"scene.sdf\"\nscene { s }\n");
  expectDiagnostics("imports_scene.sdf", "DIR/scene.sdf:2:1: error: an imported file holds only 'let' definitions and imports; this belongs in the file that imports it\n"
                "scene { s }\n"
                "^~~~~~~~~~~\n"
                "DIR/imports_scene.sdf:1:8: note: 'DIR/scene.sdf' is imported here\n"
                "import \"scene.sdf\"\n"
                "       ^~~~~~~~~~~\n");
  // A mistake inside an imported file names that file; a call's mistake is at the call.
  write("bad.sdf", "let ball = sphere(radius: -1)\nlet post(h) = cylinder(radius: 0.2, height: h)\n");
  write("uses_bad.sdf", "import \"bad.sdf\" as bad\nscene { bad.ball bad.post(-2) }\n");
  expectDiagnostics("uses_bad.sdf", "DIR/bad.sdf:1:27: error: 'radius' of 'sphere' must be positive, got -1\n"
                "let ball = sphere(radius: -1)\n"
                "                          ^~\n"
                "DIR/uses_bad.sdf:2:18: error: in this call of 'bad.post': 'height' of 'cylinder' must be positive, got -2\n"
                "scene { bad.ball bad.post(-2) }\n"
                "                 ^~~~~~~~~~~~\n"
                "DIR/bad.sdf:2:45: note: here, in the definition of 'post'\n"
                "let post(h) = cylinder(radius: 0.2, height: h)\n"
                "                                            ^\n");
  // Not a regular file (a device would never end, a directory is no scene).
  write("device.sdf", "import \"/dev/zero\"\nimport \"lib\"\nscene { sphere(radius: 1) }\n");
  fs::create_directories(dir_ / "lib");
  expectDiagnostics("device.sdf", "DIR/device.sdf:1:8: error: cannot import '/dev/zero': it is not a regular file (a FIFO, device or socket)\n"
                "import \"/dev/zero\"\n"
                "       ^~~~~~~~~~~\n"
                "DIR/device.sdf:2:8: error: cannot import 'DIR/lib': it is a directory, not a scene file\n"
                "import \"lib\"\n"
                "       ^~~~~\n");
  // An imported file sees its own names and its imports', not its importer's or a sibling's.
  write("sibling a.sdf", "let left = translate([-1, 0, 0]) { right }\n");
  write("sibling b.sdf", "let right = sphere(radius: 1)\n");
  write("siblings.sdf", "import \"sibling a.sdf\"\nimport \"sibling b.sdf\"\n"
                        "scene { left right }\n");
  expectDiagnostics("siblings.sdf", "DIR/sibling a.sdf:1:36: error: unknown name 'right'\n"
                "let left = translate([-1, 0, 0]) { right }\n"
                "                                   ^~~~~\n");
  // A syntax error in an imported file; an unknown qualified name.
  write("broken.sdf", "let x = sphere(radius: 1\n");
  write("uses_broken.sdf", "import \"broken.sdf\" as b\nscene { b.y(1) }\n");
  expectDiagnostics("uses_broken.sdf", "DIR/broken.sdf:2:1: error: expected ')' after the arguments, found end of file\n"
                "\n"
                "^\n"
                "DIR/uses_broken.sdf:2:9: error: unknown definition 'b.y'; did you mean 'b.x'?\n"
                "scene { b.y(1) }\n"
                "        ^~~\n");
}

// N files each importing the next twice (`as x`, `as y`): 20 took 35 s and
// 833 MB in check (each file was bound under every one of its 2^k prefixes).
// Each file is read and bound once now, the other prefixes aliases of it.
TEST_F(Imports, DiamondsAreLinear) {
  const int n = 20;  // 35 s and 833 MB before
  for (int i = 0; i < n; ++i) {
    const std::string next = "f" + std::to_string(i + 1) + ".sdf";
    write("f" + std::to_string(i) + ".sdf",
          i + 1 < n ? "import \"" + next + "\" as x\nimport \"" + next + "\" as y\nlet r = x.r + 0 * y.r\n"
                      "let ball = sphere(radius: y.r)\n"
                    : "let r = 0.5\nlet ball = sphere(radius: r)\n");
  }
  // Every body resolves x.r and y.r through its file's two imports.
  write("main.sdf", "import \"f0.sdf\" as x\nimport \"f0.sdf\" as y\n"
                    "scene { x.ball translate([2, 0, 0]) { y.ball } }\n");
  const auto start = std::chrono::steady_clock::now();
  const CompiledScene c = compiled("main.sdf");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
  ASSERT_TRUE(c.ok);
  EXPECT_EQ(c.scene.imported_sources.size(), size_t(n));
  EXPECT_EQ(Evaluator(c.scene).distance(glm::dvec3(2, 0, 0)), -0.5);
}

// A file bound once and imported again without `as` brings its names in
// there too: a clash with this file's own is still an error.
TEST_F(Imports, AClashThroughASecondImportOfOneFile) {
  write("w.sdf", "let wall = sphere(radius: 1)\n");
  write("main.sdf", "import \"w.sdf\" as w\nimport \"w.sdf\"\nlet wall = box(size: 1)\nscene { wall w.wall }\n");
  expectDiagnostics("main.sdf", "DIR/main.sdf:2:8: error: this import brings in 'wall', which is already defined\n"
                                "import \"w.sdf\"\n"
                                "       ^~~~~~~\n"
                                "DIR/w.sdf:1:5: note: 'wall' from 'DIR/w.sdf', imported at DIR/main.sdf:2:8 is defined here\n"
                                "let wall = sphere(radius: 1)\n"
                                "    ^~~~\n"
                                "DIR/main.sdf:3:5: note: 'wall' is defined here\n"
                                "let wall = box(size: 1)\n"
                                "    ^~~~\n");
  write("ok.sdf", "import \"w.sdf\" as w\nimport \"w.sdf\"\nscene { wall w.wall }\n");
  expectDiagnostics("ok.sdf", "");
}

// -D on a number of an imported file was accepted and ignored.
TEST_F(Imports, DefineOverridesAnImportedNumber) {
  write("lib.sdf", "let q = 1\nlet ball = sphere(radius: q)\nlet rook = sphere(radius: 2)\n");
  write("main.sdf", "import \"lib.sdf\" as l\nimport \"lib.sdf\" as m\nscene { l.ball translate([9, 0, 0]) { m.rook } }\n");
  for (const char* name : {"l.q", "m.q"}) {
    Diagnostics diags;
    CompileOptions options;
    options.produce_spirv = false;
    options.check.defines[name] = 3;
    const CompiledScene c = compileFile((dir_ / "main.sdf").string(), options, diags);
    ASSERT_TRUE(c.ok) << diags.format();
    EXPECT_EQ(Evaluator(c.scene).distance(glm::dvec3(0)), -3.0) << name;
  }
  Diagnostics diags;
  CompileOptions options;
  options.produce_spirv = false;
  options.check.defines["l.rook"] = 3;
  options.check.defines["l.nosuch"] = 3;
  const CompiledScene c = compileFile((dir_ / "main.sdf").string(), options, diags);  // the diagnostics point into it
  EXPECT_NE(diags.format().find("-D l.nosuch: the scene defines no 'let l.nosuch'"), std::string::npos) << diags.format();
  EXPECT_NE(diags.format().find("-D l.rook gives a number, but 'l.rook' is a shape"), std::string::npos) << diags.format();
}

// A misspelt imported name gets the same "did you mean" as a local one.
TEST_F(Imports, MisspeltImportedNameGetsASuggestion) {
  write("pieces.sdf", "let rook = sphere(radius: 1)\nlet pawn(h) = sphere(radius: h)\n");
  write("main.sdf", "import \"pieces.sdf\" as p\nscene { p.rok p.pwn(1) }\n");
  expectDiagnostics("main.sdf", "DIR/main.sdf:2:9: error: unknown name 'p.rok'; did you mean 'p.rook'?\n"
                                "scene { p.rok p.pwn(1) }\n"
                                "        ^~~~~\n"
                                "DIR/main.sdf:2:15: error: unknown definition 'p.pwn'; did you mean 'p.pawn'?\n"
                                "scene { p.rok p.pwn(1) }\n"
                                "              ^~~~~\n");
}

}  // namespace
}  // namespace sdfc
