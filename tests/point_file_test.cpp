// instances(positions: file("...")): the CSV rules of docs/language.md. Each
// bad row is an error at its place in the CSV (file:line:col, its line and a
// caret) with a note at the file(...) string; files that are not regular
// files or too large are refused at once; the limit `check` states on the
// instances' data is the one a render meets.
#include <gtest/gtest.h>

#include <chrono>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <future>
#include <sys/stat.h>
#include <unistd.h>

#include "check/point_file.h"
#include "driver/compile.h"
#include "vulkan_context.h"

namespace sdfc {
namespace {

namespace fs = std::filesystem;

fs::path testDir() {
  // One per test (CTest runs them in parallel); a space, as users have.
  const fs::path dir = fs::path(testing::TempDir()) /
                       ("sdfc point files " + std::string(testing::UnitTest::GetInstance()->current_test_info()->name()));
  fs::create_directories(dir);
  return dir;
}

const std::string kScene = "scene { instances(positions: file(\"p.csv\")) { sphere(radius: 0.1) } }\n";

// The diagnostics of checking kScene beside a p.csv holding `csv` ("" when clean).
std::string checkWith(const std::string& csv) {
  const fs::path dir = testDir();
  std::ofstream(dir / "p.csv", std::ios::binary) << csv;
  Diagnostics diags;
  const CompiledScene c = checkSource((dir / "s.sdf").string(), kScene, CompileOptions{}, diags);
  EXPECT_EQ(c.ok, !diags.hasErrors());
  return diags.hasErrors() ? diags.format() : "";
}

// `out` holds "p.csv:LINE:COL: error: MESSAGE" (after the directory).
void expectCsvError(const std::string& out, const std::string& where, const std::string& message) {
  EXPECT_NE(out.find("p.csv:" + where + ": error: " + message), std::string::npos) << out;
  EXPECT_NE(out.find("s.sdf:1:35: note: in the positions read from 'p.csv' here"), std::string::npos) << out;
}

TEST(PointFile, AHeaderIsARowWithNoFieldThatStartsLikeANumber) {
  EXPECT_EQ(checkWith("x,y,z\n0,0,0\n"), "");
  EXPECT_EQ(checkWith("# comment\n\n  x y z scale\n0 0 0 1\n"), "");
  // The reproducer: taken as a header and dropped without a word.
  std::string out = checkWith("1.5e,2,3\n0,0,0\n");
  expectCsvError(out, "1:1", "'1.5e' is not a decimal number (a first row is a header only when none");
  EXPECT_NE(out.find("\n1.5e,2,3\n^~~~\n"), std::string::npos) << out;  // the CSV's line and a caret
  expectCsvError(checkWith("x,2,3\n0,0,0\n"), "1:1", "'x' is not a decimal number");
  expectCsvError(checkWith("x,y,z\nx,y,z\n"), "2:1", "'x' is not a decimal number");
}

TEST(PointFile, ValuesAreFloat32LikeSceneNumbers) {
  EXPECT_EQ(checkWith("3.4e38,-3.4e38,1e-50\n"), "");
  expectCsvError(checkWith("0,0,0\n1e39,0,0\n"), "2:1", "'1e39' is beyond the range of the shader's float32");
  expectCsvError(checkWith("-1e39,-1e39,-1e39\n"), "1:1", "'-1e39' is beyond the range");
  expectCsvError(checkWith("1, 2, 1e400\n"), "1:7", "'1e400' is beyond the range");
  expectCsvError(checkWith("1e38, 0, 0, 0.01\n"), "1:1", "position / scale is beyond the range");
  expectCsvError(checkWith("1, 2, 3, -1\n"), "1:10", "scale must be positive, got -1");
}

TEST(PointFile, OnlyDecimalNumbersAndNoEmptyFields) {
  EXPECT_EQ(checkWith("1, 2, 3\n-1;+2;.5\n1.\t2e3\t3E-2\r\n4 5 6 0.5\n"), "");
  expectCsvError(checkWith("0,0,0\n0x10,0,0\n"), "2:1", "'0x10' is not a decimal number");
  expectCsvError(checkWith("0,0,0\ninf,0,0\n"), "2:1", "'inf' is not a decimal number");
  expectCsvError(checkWith("0,0,0\n1,2,nan\n"), "2:5", "'nan' is not a decimal number");
  expectCsvError(checkWith("0,0,0\n1,,2,3\n"), "2:3", "empty field");
  expectCsvError(checkWith("0,0,0\n1,2,3,\n"), "2:6", "empty field");
  expectCsvError(checkWith("0,0,0\n1 2\n"), "2:1", "expected 3 or 4 numbers (x, y, z[, scale]), found 2");
  expectCsvError(checkWith("0,0,0\n1,2,3e\n"), "2:5", "'3e' is not a decimal number");
}

TEST(PointFile, ManyBadRowsShowTheFirstFive) {
  std::string csv;
  for (int i = 0; i < 9; ++i) csv += "1,2\n";
  const std::string out = checkWith(csv);
  expectCsvError(out, "5:1", "expected 3 or 4 numbers");
  EXPECT_EQ(out.find("p.csv:6:1"), std::string::npos) << out;
  EXPECT_NE(out.find("s.sdf:1:35: error: 'p.csv' has 9 bad rows; the first 5 are shown"), std::string::npos) << out;
}

std::string checkPath(const std::string& path) {
  Diagnostics diags;
  const std::string scene = "scene { instances(positions: file(\"" + path + "\")) { sphere(radius: 0.1) } }\n";
  const CompiledScene c = checkSource((testDir() / "s.sdf").string(), scene, CompileOptions{}, diags);
  EXPECT_FALSE(c.ok);
  return diags.format();
}

TEST(PointFile, OnlyRegularFilesOfBoundedSizeAreRead) {
  const fs::path dir = testDir();
  fs::create_directories(dir / "a dir");
  std::string out = checkPath("a dir");
  EXPECT_NE(out.find("error: cannot read 'a dir': it is a directory (looked for '" + (dir / "a dir").string() + "')"),
            std::string::npos)
      << out;
  // /dev/zero never ends (it ran to 3.9 GB, then bad_alloc).
  out = checkPath("/dev/zero");
  EXPECT_NE(out.find("cannot read '/dev/zero': it is not a regular file"), std::string::npos) << out;
  // A file larger than the cap is refused before it is read (a sparse one: no disk used).
  {
    const int fd = ::open((dir / "huge.csv").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::ftruncate(fd, static_cast<off_t>(kMaxPointFileBytes) + 1), 0);
    ::close(fd);
  }
  out = checkPath("huge.csv");
  EXPECT_NE(out.find("bytes, at most 256 MiB"), std::string::npos) << out;
  fs::remove(dir / "huge.csv");
}

TEST(PointFile, AFifoIsRefusedWithoutWaitingForAWriter) {
  const fs::path fifo = testDir() / "points.fifo";
  fs::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  auto result = std::async(std::launch::async, [&] { return checkPath("points.fifo"); });
  const bool finished = result.wait_for(std::chrono::seconds(10)) == std::future_status::ready;
  if (!finished) {
    // It blocked in open(): a writer that opens and closes releases it.
    const int fd = ::open(fifo.c_str(), O_WRONLY);
    if (fd >= 0) ::close(fd);
  }
  const std::string out = result.get();
  EXPECT_TRUE(finished) << "check blocked on a FIFO";
  EXPECT_NE(out.find("it is not a regular file (a FIFO, device or socket)"), std::string::npos) << out;
  fs::remove(fifo);
}

// 8,388,608 rows (the row limit) passed `check` and failed 30 s into the
// render on the storage buffer's size. Now `check` builds the instances' data
// as the emitter does and holds it to the limit every render meets.
TEST(PointFile, CheckHoldsTheInstancesDataToTheLimitARenderMeets) {
  const fs::path dir = testDir();
  {
    std::ofstream f(dir / "grid.csv");
    for (int i = 0; i < 2000; ++i) f << i % 40 << "," << (i / 40) % 10 << "," << i / 400 << "\n";
  }
  const std::string scene = "scene { instances(positions: file(\"grid.csv\")) { box(size: 0.5) } }\n";
  const std::string path = (dir / "s.sdf").string();
  CompileOptions options;
  options.produce_spirv = false;
  Diagnostics d0;
  const CompiledScene full = compileSource(path, scene, options, d0);
  ASSERT_TRUE(full.ok) << d0.format();
  const size_t bytes = full.emitted.scene_data.size() * sizeof(float);
  ASSERT_GT(bytes, 2000u * 16);
  for (const size_t limit : {bytes - 4, bytes}) {
    options.max_scene_data_bytes = limit;
    Diagnostics d1, d2;
    const CompiledScene checked = checkSource(path, scene, options, d1);
    const CompiledScene compiled = compileSource(path, scene, options, d2);
    EXPECT_EQ(checked.ok, limit >= bytes) << d1.format();
    EXPECT_EQ(compiled.ok, limit >= bytes) << d2.format();
    if (limit < bytes)
      EXPECT_NE(d1.format().find("s.sdf:1:9: error: the instances' data (their records, grid and hierarchy) would take " +
                                 std::to_string(bytes) + " bytes; at most " + std::to_string(limit)),
                std::string::npos)
          << d1.format();
  }
  // The limit itself: what Vulkan guarantees, and what lavapipe has (a larger
  // device renders more, but then `check` would pass scenes others refuse).
  EXPECT_EQ(kMaxSceneDataBytes, size_t(1) << 27);
  VulkanContext context;
  createContext(context);
  EXPECT_GE(context.properties.limits.maxStorageBufferRange, kMaxSceneDataBytes) << context.deviceName();
  destroyContext(context);
}

}  // namespace
}  // namespace sdfc
