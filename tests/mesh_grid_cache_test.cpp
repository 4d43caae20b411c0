// The on-disk cache of meshes' sampled grids (meshin/mesh_grid_cache.h): a hit
// gives the grid a build gives, bit for bit; a damaged entry is ignored and
// replaced; another mesh or layout has another entry; no version, no cache.
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "driver/compile.h"
#include "meshin/mesh_grid_cache.h"
#include "meshin/mesh_shape.h"
#include "mesh_soup.h"

namespace sdfc {
namespace {

namespace fs = std::filesystem;

class MeshGridCache : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("sdfc grid cache " + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    const char* old = std::getenv("XDG_CACHE_HOME");
    had_ = old != nullptr;
    if (had_) old_ = old;
    setenv("XDG_CACHE_HOME", (dir_ / "cache").c_str(), 1);
  }
  void TearDown() override {
    if (had_) setenv("XDG_CACHE_HOME", old_.c_str(), 1);
    else unsetenv("XDG_CACHE_HOME");
    fs::remove_all(dir_);
  }
  // The scene's one mesh, read afresh (its own once-built grid).
  const MeshShape& load(const test::Soup& soup) {
    const std::string stl = (dir_ / "part.stl").string();
    std::ofstream(stl, std::ios::binary) << test::binaryStl(soup);
    const std::string text = "scene {\n  mesh(file: \"part.stl\")\n}\n";
    CompileOptions o;
    o.produce_spirv = false;
    o.emit.with_kernel = false;
    o.check.mesh_mode = MeshMode::Grid;
    Diagnostics diags;
    compiled_.push_back(std::make_unique<CompiledScene>(
        checkSource((dir_ / "scene.sdf").string(), text, o, diags)));
    EXPECT_FALSE(diags.hasErrors());
    const ir::Node& root = *compiled_.back()->scene.root;
    return root.kind == ir::NodeKind::Mesh ? *root.mesh : *root.children.at(0)->mesh;
  }
  size_t entries() const {
    const fs::path d = dir_ / "cache" / "sdfc" / "mesh-grid";
    if (!fs::exists(d)) return 0;
    return size_t(std::distance(fs::directory_iterator(d), fs::directory_iterator()));
  }

  fs::path dir_;
  bool had_ = false;
  std::string old_;
  std::vector<std::unique_ptr<CompiledScene>> compiled_;
};

TEST_F(MeshGridCache, AHitIsTheBuiltGridBitForBit) {
  const test::Soup ico = test::icosphere(2);
  const MeshGrid& built = load(ico).grid("v1");
  EXPECT_FALSE(built.from_cache);
  EXPECT_EQ(entries(), 1u);
  const MeshGrid& again = load(ico).grid("v1");
  EXPECT_TRUE(again.from_cache);
  ASSERT_EQ(again.values.size(), built.values.size());
  EXPECT_EQ(std::memcmp(again.values.data(), built.values.data(), built.values.size() * sizeof(float)), 0);
  // Without a version (a library user, a test, --no-cache) the cache is not read.
  EXPECT_FALSE(load(ico).grid("").from_cache);
  // Another version, another mesh: other entries.
  EXPECT_FALSE(load(ico).grid("v2").from_cache);
  EXPECT_FALSE(load(test::icosphere(2, 1.5)).grid("v1").from_cache);
  EXPECT_EQ(entries(), 3u);
}

TEST_F(MeshGridCache, ADamagedEntryIsIgnoredAndReplaced) {
  const test::Soup ico = test::icosphere(2);
  const MeshShape& first = load(ico);
  const std::vector<float> want = first.grid("v1").values;
  const std::string key = meshGridCacheKey(*first.distance, first.grid_layout, "v1");
  const std::string path = meshGridCachePath(key);
  ASSERT_TRUE(fs::exists(path));
  {
    // One value's bytes changed: the checksum no longer matches.
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(-4, std::ios::end);
    const float bad = 1234.5f;
    f.write(reinterpret_cast<const char*>(&bad), sizeof bad);
  }
  const MeshGrid& rebuilt = load(ico).grid("v1");
  EXPECT_FALSE(rebuilt.from_cache);
  EXPECT_EQ(rebuilt.values, want);
  EXPECT_TRUE(load(ico).grid("v1").from_cache);  // the rebuild replaced it
  // A truncated entry too.
  fs::resize_file(path, fs::file_size(path) / 2);
  EXPECT_FALSE(load(ico).grid("v1").from_cache);
  EXPECT_TRUE(load(ico).grid("v1").from_cache);
}

}  // namespace
}  // namespace sdfc
