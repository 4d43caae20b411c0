// The reader fuzz targets' seeds (fuzz/corpus-*, written by fuzz/seeds.py) are
// odd but valid files: each reader accepts each one, with what the seed holds,
// so the fuzzers start inside the formats. Files named regression_* are inputs
// the fuzzers once broke a reader with: refused with a reason.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "check/env_map_file.h"
#include "check/image_file.h"
#include "check/point_file.h"
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

}  // namespace
}  // namespace sdfc
