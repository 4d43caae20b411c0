// Issue 18: bad input that once slipped through. Scene files live in
// fuzz/regressions/issue18_*.sdf (and issue29_*.sdf: one mistake, one
// message), each headed by what it must give:
//   // expect: error: <text>        the diagnostics contain "error: <text>"
//   // expect-at: <file:l:c: ...>  the diagnostics contain this (path "t.sdf")
//   // expect-count: N             exactly N errors
//   // expect-warnings: N          exactly N warnings (after `// sdfc: allow(...)`)
//   // expect: compiles            no errors, and the scene compiles to SPIR-V
// Writers: the checked, unique-temporary writer (runtime/atomic_file.h).
// The command line's exit codes are in tests/cli_bad_input_test.sh.
#include <gtest/gtest.h>

#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "atomic_file.h"
#include "driver/compile.h"
#include "image_io.h"

namespace sdfc {
namespace {

namespace fs = std::filesystem;

std::string readAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

struct Expectations {
  std::vector<std::string> contains;
  int error_count = -1;
  int warning_count = -1;
  bool compiles = false;
};

Expectations expectationsOf(const std::string& text) {
  Expectations e;
  size_t pos = 0;
  while (pos < text.size() && text.compare(pos, 3, "// ") == 0) {
    size_t end = text.find_first_of("\r\n", pos);
    if (end == std::string::npos) end = text.size();
    const std::string line = text.substr(pos + 3, end - pos - 3);
    if (line == "expect: compiles") e.compiles = true;
    else if (line.rfind("expect: ", 0) == 0) e.contains.push_back(line.substr(8));
    else if (line.rfind("expect-at: ", 0) == 0) e.contains.push_back(line.substr(11));
    else if (line.rfind("expect-count: ", 0) == 0) e.error_count = std::stoi(line.substr(14));
    else if (line.rfind("expect-warnings: ", 0) == 0) e.warning_count = std::stoi(line.substr(17));
    pos = end + 1;
  }
  return e;
}

TEST(BadInput, Issue18RegressionsGiveTheirDiagnosticOrCompile) {
  int files = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(SDFC_SOURCE_DIR) / "fuzz/regressions")) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("issue18_", 0) != 0 && name.rfind("issue29_", 0) != 0) continue;
    SCOPED_TRACE(entry.path().string());
    ++files;
    const std::string text = readAll(entry.path());
    const Expectations want = expectationsOf(text);
    ASSERT_TRUE(want.compiles || !want.contains.empty()) << "no '// expect' header";
    Diagnostics diags;
    const CompiledScene compiled = compileSource("t.sdf", text, {}, diags);
    const std::string out = diags.format();
    for (const std::string& c : want.contains) EXPECT_NE(out.find(c), std::string::npos) << c << "\n" << out;
    if (want.error_count >= 0) {
      EXPECT_EQ(diags.errorCount(), want.error_count) << out;
    }
    if (want.warning_count >= 0) EXPECT_EQ(diags.warningCount(), want.warning_count) << out;
    if (want.compiles) {
      EXPECT_FALSE(diags.hasErrors()) << out;
      EXPECT_TRUE(compiled.ok && !compiled.spirv.empty()) << out;
    }
    // A checked scene always compiles: no internal error may reach the user.
    EXPECT_EQ(out.find("internal error"), std::string::npos) << out;
  }
  EXPECT_GE(files, 23);
}

std::string diagnosticsFor(const std::string& text, const CheckOptions& check = {}) {
  Diagnostics diags;
  CompileOptions options;
  options.check = check;
  const CompiledScene compiled = compileSource("t.sdf", text, options, diags);
  return diags.format();
}

TEST(BadInput, DefinesBeyondFloat32AreSceneErrorsNotInternalErrors) {
  for (double value : {double(INFINITY), 1e39, -1e300}) {
    CheckOptions check;
    check.defines["r"] = value;
    const std::string out = diagnosticsFor("let r = 1\nscene { sphere(radius: r) }\n", check);
    EXPECT_NE(out.find("beyond the range of the shader's float32 numbers"), std::string::npos) << out;
    EXPECT_EQ(out.find("internal error"), std::string::npos) << out;
  }
}

TEST(BadInput, FloatRangeOverTimeIsAWarningWhenOnlySometimesExceeded) {
  const std::string out = diagnosticsFor("scene { translate([1e30 * sin(time) * 1e9, 0, 0]) { sphere(radius: 1) } }");
  EXPECT_NE(out.find("warning: a component of 'offset' of 'translate' ranges over [-1e+39, 1e+39]"),
            std::string::npos)
      << out;
}

TEST(BadInput, MorphWithinTheStretchLimitCompiles) {
  Diagnostics diags;
  const CompiledScene c =
      compileSource("t.sdf", "scene { morph(t: 3 * sin(time)) { box(size: 1) sphere(1) } }", {}, diags);
  EXPECT_TRUE(c.ok) << diags.format();
  EXPECT_NE(diagnosticsFor("scene { morph(t: 5 * sin(time)) { box(size: 1) sphere(1) } }").find("at most 8"),
            std::string::npos);
}

TEST(BadInput, SceneSizeIsLimitedWithTheCountInTheMessage) {
  // Copies placed over time cannot become data (passes/instancing.cpp): all code.
  std::string text = "scene {\n";
  for (int i = 0; i < 2100; ++i)
    text += "translate([" + std::to_string(i) + ", 0.1 * time, 0]) { sphere(radius: 0.4) }\n";
  text += "}\n";
  Diagnostics diags;
  const CompiledScene c = checkSource("t.sdf", text, {}, diags);
  EXPECT_NE(diags.format().find("error: the scene has 4201 shapes and operations as shader code"),
            std::string::npos)
      << diags.format();
  // A named shape counts once, however often it is used.
  std::string shared = "let s = translate([1, 0, 0]) { sphere(radius: 0.4) }\nscene {\n";
  for (int i = 0; i < 2100; ++i) shared += "s\n";
  Diagnostics ok;
  const CompiledScene c2 = checkSource("t.sdf", shared + "}\n", {}, ok);
  EXPECT_FALSE(ok.hasErrors()) << ok.format();
  // Constant placements of one shape become data, whatever their number.
  std::string placed = "scene {\n";
  for (int i = 0; i < 5000; ++i)
    placed += "translate([" + std::to_string(i) + ", 0, 0]) { box(size: [0.5, 0.5, 0.5]) }\n";
  Diagnostics data;
  const CompiledScene c3 = checkSource("t.sdf", placed + "}\n", {}, data);
  EXPECT_FALSE(data.hasErrors()) << data.format();
}

TEST(BadInput, FlatSumsAreLimitedByTreeHeightWithOneError) {
  std::string sum = "let x = 1";
  for (int i = 0; i < 5000; ++i) sum += " + 1";
  Diagnostics diags;
  const CompiledScene c = checkSource("t.sdf", sum + "\nscene { sphere(radius: x) }\n", {}, diags);
  EXPECT_EQ(diags.errorCount(), 1) << diags.format();
  EXPECT_NE(diags.format().find("more than 1000 levels deep"), std::string::npos);
}

TEST(BadInput, ColumnsCountCodePointsAndCrEndsALine) {
  SourceFile file("t.sdf", "\xc3\xa9\xc3\xa8x\ry\r\nz\n");
  EXPECT_EQ(file.lineColumn(4), std::make_pair(1, 3));  // 'x' after two 2-byte letters
  EXPECT_EQ(file.lineColumn(6), std::make_pair(2, 1));  // 'y' after a lone CR
  EXPECT_EQ(file.lineColumn(9), std::make_pair(3, 1));  // 'z' after CRLF
  EXPECT_EQ(file.lineText(1), "\xc3\xa9\xc3\xa8x");
  EXPECT_EQ(file.lineText(2), "y");
  // The caret sits under the character in the printed line.
  const std::string out = diagnosticsFor("let \xc3\xa9 = 1 + $\nscene { sphere(radius: 1) }\n");
  EXPECT_NE(out.find("t.sdf:1:5: error: unexpected character U+00E9 '\xc3\xa9'"), std::string::npos) << out;
  EXPECT_NE(out.find("t.sdf:1:13: error: unexpected character '$'\nlet \xc3\xa9 = 1 + $\n            ^\n"),
            std::string::npos)
      << out;
}

TEST(BadInput, ReadingADirectoryAsASceneFails) {
  EXPECT_EQ(readSourceFile(SDFC_SOURCE_DIR), nullptr);
}

// ---- writers ---------------------------------------------------------------

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(SDFC_BINARY_DIR) / "bad_input_test" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::vector<std::string> namesIn(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(BadInputWrites, ConcurrentWritersNeverShareATemporary) {
  const fs::path dir = scratch("concurrent");
  const fs::path target = dir / "out.glsl";
  std::vector<std::thread> threads;
  std::atomic<int> failures{0};
  std::vector<std::string> payloads;
  for (int i = 0; i < 24; ++i) payloads.push_back(std::string(100000 + i, char('a' + i)));
  for (int i = 0; i < 24; ++i)
    threads.emplace_back([&, i] {
      try {
        writeFileAtomically(target.string(), payloads[i]);
      } catch (const std::exception&) {
        ++failures;
      }
    });
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(failures.load(), 0);
  const std::string final_bytes = readAll(target);
  EXPECT_NE(std::find(payloads.begin(), payloads.end(), final_bytes), payloads.end());
  EXPECT_EQ(namesIn(dir), std::vector<std::string>{"out.glsl"});  // no temporaries left
}

TEST(BadInputWrites, StaleTemporariesAreIgnored) {
  const fs::path dir = scratch("stale");
  // What an old writer (or SIGKILL mid-write) leaves: "<path>.tmp", even one we cannot replace.
  fs::create_directories(dir / "out.png.tmp");
  std::ofstream(dir / ".out.png.AAAAAA") << "junk";
  FloatImage image{4, 4, 0.5f};
  writeImage((dir / "out.png").string(), image);
  EXPECT_EQ(readImage((dir / "out.png").string()).width, 4u);
}

TEST(BadInputWrites, FifosAndDevicesAreWrittenInPlace) {
  const fs::path dir = scratch("fifo");
  const fs::path fifo = dir / "pipe.glsl";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::string received;
  std::thread reader([&] { received = readAll(fifo); });
  writeFileAtomically(fifo.string(), "void main() {}\n");
  reader.join();
  EXPECT_EQ(received, "void main() {}\n");
  struct stat st;
  ASSERT_EQ(::stat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));  // not replaced by a regular file
  writeFileAtomically("/dev/null", "x");
  ASSERT_EQ(::stat("/dev/null", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode));
  // A device that fails the write (a full disk) is an error, not a success.
  EXPECT_THROW(writeFileAtomically("/dev/full", std::string(1 << 16, 'x')), FileWriteError);
}

// A full disk, simulated with RLIMIT_FSIZE (writes past it fail with EFBIG):
// every format fails cleanly and the previous file stays whole.
TEST(BadInputWrites, AFullDiskFailsEveryFormatAndKeepsThePreviousFile) {
  const fs::path dir = scratch("full");
  FloatImage small{4, 4, 0.25f};
  FloatImage big{256, 256};
  for (size_t i = 0; i < big.rgba.size(); ++i) big.rgba[i] = float((i * 7919) % 1000) / 1000.0f;
  for (const char* name : {"a.png", "a.exr", "a.pfm"}) {
    SCOPED_TRACE(name);
    const std::string path = (dir / name).string();
    writeImage(path, small);
    const std::string before = readAll(path);
    struct rlimit old_limit;
    ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &old_limit), 0);
    struct rlimit limit = old_limit;
    limit.rlim_cur = 4096;
    auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
    ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &limit), 0);
    EXPECT_THROW(writeImage(path, big), ImageIoError);
    ::setrlimit(RLIMIT_FSIZE, &old_limit);
    std::signal(SIGXFSZ, old_handler);
    EXPECT_EQ(readAll(path), before);
  }
  EXPECT_EQ(namesIn(dir), (std::vector<std::string>{"a.exr", "a.pfm", "a.png"}));
}

TEST(BadInputWrites, OutputPathsAreCheckedBeforeWork) {
  const fs::path dir = scratch("paths");
  EXPECT_NO_THROW(checkWritablePath((dir / "x.png").string()));
  EXPECT_NO_THROW(checkWritablePath("-"));
  EXPECT_NO_THROW(checkWritablePath("/dev/null"));
  EXPECT_THROW(checkWritablePath((dir / "missing" / "x.png").string()), FileWriteError);
  EXPECT_THROW(checkWritablePath(dir.string()), FileWriteError);
}

}  // namespace
}  // namespace sdfc
