// The reader fuzz targets' seeds (fuzz/corpus-*, written by fuzz/seeds.py) are
// odd but valid files: each reader accepts each one, with what the seed holds,
// so the fuzzers start inside the formats. Files named regression_* are inputs
// the fuzzers once broke a reader with: refused with a reason.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "check/env_map_file.h"
#include "check/image_file.h"
#include "check/point_file.h"
#include "driver/compile.h"
#include "fuzz/dispatch_input.h"
#include "lsp/server.h"
#include "lsp/transport.h"
#include "meshin/mesh_file.h"

namespace sdfc {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> seeds(const char* kind) {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(fs::path(SDFC_SOURCE_DIR) / "fuzz" / (std::string("corpus-") + kind)))
    out.push_back(e.path());
  std::sort(out.begin(), out.end());
  EXPECT_FALSE(out.empty()) << kind;
  return out;
}

// Inputs the fuzzers once broke a reader with, and seeds of what sdfc refuses.
bool isRegression(const fs::path& p) {
  const std::string name = p.filename().string();
  return name.rfind("regression_", 0) == 0 || name.find("_refused.") != std::string::npos;
}

TEST(FuzzSeeds, MeshSeedsAreValidMeshes) {
  for (const fs::path& p : seeds("mesh")) {
    const MeshFile m = readMeshFile(p.string());
    if (isRegression(p)) {
      EXPECT_FALSE(m.ok || m.error.empty()) << p;
      continue;
    }
    EXPECT_TRUE(m.ok) << p << ": " << m.error;
    EXPECT_GE(m.mesh.triangles.size(), 4u) << p;
  }
}

TEST(FuzzSeeds, ImageSeedsAreValidTexturesAndMaps) {
  for (const fs::path& p : seeds("image")) {
    const ImageFile texture = readImageFile(p.string());
    if (isRegression(p)) {
      EXPECT_TRUE(!texture.image && !texture.reason.empty()) << p;
      continue;
    }
    ASSERT_TRUE(texture.image) << p << ": " << texture.reason;
    EXPECT_GT(texture.image->width, 0) << p;
    EXPECT_EQ(texture.image->rgb.size(), size_t(texture.image->width) * texture.image->height * 3) << p;
    if (p.extension() != ".png") {
      const EnvMapFile map = readEnvMapFile(p.string());
      EXPECT_TRUE(map.image) << p << ": " << map.reason;
    }
  }
}

TEST(FuzzSeeds, PointSeedsAreValidLists) {
  for (const fs::path& p : seeds("points")) {
    const PointFile f = readPointFile(p.string());
    EXPECT_TRUE(f.readable) << p;
    EXPECT_EQ(f.bad_rows, 0u) << p << ": " << (f.errors.empty() ? "" : f.errors[0].message);
    EXPECT_FALSE(f.rows.empty()) << p;
  }
}

TEST(FuzzSeeds, LspSeedsAreWholeFrames) {
  for (const fs::path& p : seeds("lsp")) {
    std::ifstream in(p, std::ios::binary);
    int frames = 0;
    while (std::optional<lsp::Frame> f = lsp::readFrame(in)) {
      EXPECT_FALSE(f->malformed || f->too_large) << p;
      EXPECT_FALSE(f->body.empty()) << p;
      ++frames;
    }
    EXPECT_GE(frames, 1) << p;
  }
}

// sdfc_import_fuzz's seeds: a scene and its imports, cut at NUL bytes. Each
// checks without errors (those named *_refused.* with errors), through the
// same machinery the fuzzer drives.
TEST(FuzzSeeds, ImportSeedsCheck) {
  const fs::path dir = fs::temp_directory_path() / ("sdfc_import_seeds_" + std::to_string(::getpid()));
  for (const fs::path& p : seeds("import")) {
    fs::remove_all(dir);
    fs::create_directories(dir);
    std::ifstream in(p, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::vector<std::string> parts =
        fuzz::importParts(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size(), 5);
    for (size_t i = 0; i < parts.size(); ++i)
      std::ofstream(dir / (i == 0 ? std::string("main.sdf") : std::to_string(i) + ".sdf"), std::ios::binary)
          << parts[i];
    Diagnostics diags;
    const CompiledScene compiled = checkSource((dir / "main.sdf").string(), parts[0], CompileOptions{}, diags);
    if (isRegression(p)) {
      EXPECT_TRUE(diags.hasErrors()) << p;
    } else {
      EXPECT_TRUE(compiled.ok && !diags.hasErrors()) << p << ":\n" << diags.format();
    }
  }
  fs::remove_all(dir);
}

// sdfc_lsp_dispatch_fuzz's seeds: message bodies, one a line, after the
// server's initialize and didOpen. Every request gets one answer, a result
// (errors only in *_refused.* seeds), and the server ends after exit.
TEST(FuzzSeeds, LspDispatchSeedsAreAnswered) {
  for (const fs::path& p : seeds("lsp-dispatch")) {
    std::ifstream file(p, std::ios::binary);
    const std::string lines((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    std::set<std::string> asked = {"0", "\"last\""};
    std::istringstream each(lines);
    for (std::string line; std::getline(each, line);) {
      const nlohmann::json m = nlohmann::json::parse(line);
      if (m.contains("id") && m.contains("method")) asked.insert(m["id"].dump());
    }
    std::istringstream in(fuzz::dispatchStream(lines));
    std::ostringstream out;
    EXPECT_EQ(lsp::runServer(in, out), 0) << p;
    std::istringstream replies(out.str());
    std::set<std::string> answered;
    while (std::optional<lsp::Frame> f = lsp::readFrame(replies)) {
      const nlohmann::json m = nlohmann::json::parse(f->body);
      if (!m.contains("id")) continue;  // diagnostics and log messages
      EXPECT_TRUE(answered.insert(m["id"].dump()).second) << p << ": two answers to " << m["id"];
      if (!isRegression(p)) {
        EXPECT_FALSE(m.contains("error")) << p << ": " << f->body;
      }
    }
    EXPECT_EQ(answered, asked) << p;
  }
}

}  // namespace
}  // namespace sdfc
