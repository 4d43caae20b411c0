// Farm shards without a cluster: the pass-aligned sample split, the shard file's
// round trip, merge refusals, and the central claim: shards rendered separately
// and merged equal one render of the whole sample range bit for bit (the Slurm
// tests in tests/slurm/ check the same through sbatch).
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "farm_support.h"
#include "image_io.h"
#include "shard_merge.h"
#include "slurm.h"

namespace sdfc {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(SDFC_BINARY_DIR) / "farm_test" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(FarmPlan, SlicesTileTheSamplesOnPassBoundaries) {
  for (uint32_t spp : {1u, 7u, 64u, 100u, 4096u})
    for (uint32_t per_pass : {1u, 3u, 31u, 64u})
      for (uint32_t slices : {1u, 2u, 5u, 8u, 64u}) {
        const uint32_t passes = (spp + per_pass - 1) / per_pass;
        if (slices > passes) {
          EXPECT_THROW(farm::splitSamples(spp, per_pass, slices), farm::FarmError);
          continue;
        }
        const auto ranges = farm::splitSamples(spp, per_pass, slices);
        ASSERT_EQ(ranges.size(), slices);
        uint32_t next = 0, smallest = ~0u, largest = 0;
        for (const farm::SampleRange& r : ranges) {
          EXPECT_EQ(r.begin, next);
          EXPECT_EQ(r.begin % per_pass, 0u);
          EXPECT_GT(r.end, r.begin);
          next = r.end;
          const uint32_t range_passes = (r.count() + per_pass - 1) / per_pass;
          smallest = std::min(smallest, range_passes);
          largest = std::max(largest, range_passes);
        }
        EXPECT_EQ(next, spp);
        EXPECT_LE(largest - smallest, 1u);
      }
}

TEST(FarmPlan, TaskIndexMapsToFrameAndSlice) {
  farm::ShardPlan plan;
  plan.spp = 64;
  plan.samples_per_pass = 8;
  plan.slices = 4;
  plan.first_frame = 10;
  plan.last_frame = 15;
  EXPECT_EQ(plan.taskCount(), 24u);
  const farm::ShardTask t = plan.task(13);
  EXPECT_EQ(t.frame, 13);
  EXPECT_EQ(t.slice, 1u);
  EXPECT_EQ(t.samples.begin, 16u);
  EXPECT_EQ(t.samples.end, 32u);
  EXPECT_THROW(plan.task(24), farm::FarmError);
  EXPECT_EQ(farm::framePath("out/frame.exr", 7), "out/frame_0007.exr");
  EXPECT_EQ(farm::arraySpec({0, 1, 2, 5, 7, 8}), "0-2,5,7-8");
  EXPECT_THROW(farm::parseFrameRange("5-2"), farm::FarmError);
}

TEST(FarmShardFile, SumsAndHeaderSurviveTheRoundTrip) {
  const fs::path dir = scratch("roundtrip");
  farm::ShardImage shard;
  farm::ShardHeader& h = shard.header;
  h.scene_hash = "0123456789abcdef";
  h.kernel_hash = "fedcba9876543210";
  h.version = "0.1.0";
  h.device = "llvmpipe";
  h.driver = "vendor 10005";
  h.settings = "5x3 spp=9";
  h.width = 5;
  h.height = 3;
  h.seed = 42;
  h.spp = 9;
  h.samples_per_pass = 3;
  h.slices = 3;
  h.slice = 1;
  h.frame = 17;
  h.time = 0.1;
  h.samples = {3, 6};
  std::mt19937_64 random(7);
  for (int i = 0; i < 45; ++i) {
    // Full 128-bit patterns, negative ones too (a depth of -1 is a valid sum).
    const SampleSum v = (SampleSum(int64_t(random())) << 64) | SampleSum(random());
    shard.sums.push_back(v);
  }
  const std::string path = (dir / "shard.exr").string();
  farm::writeShard(path, shard);
  const farm::ShardImage back = farm::readShard(path);
  EXPECT_TRUE(back.sums == shard.sums);
  EXPECT_EQ(farm::headerMismatch(back.header, h), "");
  EXPECT_EQ(back.header.frame, 17);
  EXPECT_EQ(back.header.time, 0.1);
  EXPECT_EQ(back.header.samples.begin, 3u);
  EXPECT_EQ(back.header.samples.end, 6u);
  EXPECT_EQ(back.header.slice, 1u);
  // A plain EXR is refused with its name.
  writeImage((dir / "plain.exr").string(), FloatImage(4, 4, 0.5f));
  try {
    farm::readShardHeader((dir / "plain.exr").string());
    ADD_FAILURE() << "a plain EXR was read as a shard";
  } catch (const farm::FarmError& e) {
    EXPECT_NE(std::string(e.what()).find("plain.exr: not an sdfc shard"), std::string::npos) << e.what();
  }
}

// A shard replaced between the header check and the pixels (a resubmitted job
// writing it again) was merged silently into a wrong image: the pixels must
// come from the file whose header was checked.
TEST(FarmShardFile, AShardReplacedAfterTheCheckIsRefused) {
  const fs::path dir = scratch("replaced");
  auto shardFor = [](uint32_t begin, uint32_t seed, uint64_t value) {
    farm::ShardImage shard;
    farm::ShardHeader& h = shard.header;
    h.scene_hash = "0123456789abcdef";
    h.kernel_hash = "fedcba9876543210";
    h.version = "0.1.0";
    h.device = "llvmpipe";
    h.driver = "vendor 10005";
    h.settings = "2x2 spp=6";
    h.width = 2;
    h.height = 2;
    h.seed = seed;
    h.spp = 6;
    h.samples_per_pass = 3;
    h.slices = 2;
    h.slice = begin / 3;
    h.samples = {begin, begin + 3};
    shard.sums.assign(12, SampleSum(value));
    return shard;
  };
  const std::string a = (dir / "shard_00000.exr").string(), b = (dir / "shard_00001.exr").string();
  farm::writeShard(a, shardFor(0, 1, 100));
  farm::writeShard(b, shardFor(3, 1, 200));
  const farm::ShardSet set = farm::checkShards(farm::findShards({dir.string()}));
  int merged = 0;
  farm::mergeShards(set, [&](int, const FloatImage&, const std::vector<ExrChannel>&) { ++merged; });
  EXPECT_EQ(merged, 1);  // unchanged: merges
  for (int replacement = 0; replacement < 2; ++replacement) {
    // 0: the same header, other sums (a new file renamed over it); 1: another seed.
    farm::writeShard(b, shardFor(3, replacement == 0 ? 1 : 2, 999));
    try {
      farm::mergeShards(set, [&](int, const FloatImage&, const std::vector<ExrChannel>&) {
        ADD_FAILURE() << "a replaced shard was merged";
      });
      ADD_FAILURE() << "no error for replacement " << replacement;
    } catch (const farm::FarmError& e) {
      EXPECT_NE(std::string(e.what()).find("shard_00001.exr changed after its header was checked"),
                std::string::npos) << e.what();
    }
  }
}

// A --layers shard: four sums a pixel (r, g, b, squared luminance) and the
// centre ray's float channels come back as written; a plain header refuses them.
TEST(FarmShardFile, LayeredShardSurvivesTheRoundTrip) {
  const fs::path dir = scratch("roundtrip_layers");
  farm::ShardImage shard;
  farm::ShardHeader& h = shard.header;
  h.scene_hash = h.kernel_hash = h.version = h.device = h.driver = h.settings = "x";
  h.width = 4;
  h.height = 2;
  h.spp = 8;
  h.samples_per_pass = 4;
  h.samples = {0, 4};
  h.layers = true;
  std::mt19937_64 random(11);
  for (int i = 0; i < 8 * 4; ++i) shard.sums.push_back((SampleSum(int64_t(random())) << 64) | SampleSum(random()));
  shard.features = {{"Z", std::vector<float>(8, 2.5f)}, {"object", {0, 1, 2, -1, 0, 1, 2, -1}}};
  const std::string path = (dir / "shard.exr").string();
  farm::writeShard(path, shard);
  const farm::ShardImage back = farm::readShard(path);
  EXPECT_TRUE(back.header.layers);
  EXPECT_TRUE(back.sums == shard.sums);
  ASSERT_EQ(back.features.size(), 2u);
  EXPECT_EQ(back.features[0].name, "Z");
  EXPECT_TRUE(back.features[1].values == shard.features[1].values);
  EXPECT_EQ(farm::headerMismatch(back.header, h), "");
  farm::ShardHeader plain = h;
  plain.layers = false;
  EXPECT_EQ(farm::headerMismatch(plain, h), "layers: '0' vs '1'");
  // A plain shard's three sums a pixel are no layered shard's four.
  shard.header.layers = false;
  EXPECT_THROW(farm::writeShard(path, shard), farm::FarmError);
}

// Renders examples/castle.sdf in shards through the same code as
// `sdfc render --shards` and merges them like `sdfc merge`.
class FarmRender : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { createContext(context_); }
  static void TearDownTestSuite() { destroyContext(context_); }

  void SetUp() override {
    cl_.input = std::string(SDFC_SOURCE_DIR) + "/examples/castle.sdf";
    cl_.size = "40x24";
    cl_.spp = 186;  // 6 passes of 31 (the castle's loop budget sets the pass size)
    cl_.seed = 5;
    ASSERT_TRUE(renderOverridesFrom(cl_, o_));
    Diagnostics diags;
    loaded_ = compileForDevice(cl_, context_, o_);
    ASSERT_EQ(loaded_.exit_code, kExitOk);
  }

  // Writes shards [0, job.plan.taskCount()) into `dir`.
  ShardJob writeShards(const fs::path& dir, int slices) {
    cl_.shards = slices;
    ShardJob job = shardJobFor(cl_, o_, loaded_.compiled);
    Renderer renderer(context_, loaded_.compiled);
    for (uint32_t i = 0; i < job.plan.taskCount(); ++i) {
      farm::ShardImage shard;
      shard.header = expectedHeader(job, i);
      shard.header.device = deviceText(context_);
      shard.header.driver = driverText(context_);
      renderShard(renderer, loaded_.compiled, job, shard);
      farm::writeShard((dir / farm::shardFileName(i)).string(), shard);
    }
    return job;
  }

  FloatImage mergeDir(const fs::path& dir) {
    FloatImage merged;
    farm::mergeShards(farm::checkShards(farm::findShards({dir.string()})),
                      [&](int, const FloatImage& image, const std::vector<ExrChannel>&) { merged = image; });
    return merged;
  }

  static VulkanContext context_;
  CommandLine cl_;
  RenderOverrides o_;
  LoadedScene loaded_;
};
VulkanContext FarmRender::context_;

TEST_F(FarmRender, MergedShardsEqualTheSingleRenderBitForBit) {
  Renderer renderer(context_, loaded_.compiled);
  const RenderOutput single =
      renderer.render(cameraFor(loaded_.compiled.scene), renderSettingsFor(loaded_.compiled, o_));
  const fs::path dir = scratch("bits");
  const ShardJob job = writeShards(dir, 3);
  ASSERT_GE(single.passes, 3u) << "the test needs several passes per shard";
  ASSERT_EQ(job.plan.samples_per_pass, single.samples_per_pass);
  const FloatImage merged = mergeDir(dir);
  ASSERT_EQ(merged.rgba.size(), single.color.rgba.size());
  EXPECT_TRUE(std::memcmp(merged.rgba.data(), single.color.rgba.data(), merged.rgba.size() * 4) == 0);
  // The same through the files sdfc writes: identical bytes.
  writeImage((dir / "single.exr").string(), single.color);
  writeImage((dir / "merged.exr").string(), merged);
  std::ifstream a(dir / "single.exr", std::ios::binary), b(dir / "merged.exr", std::ios::binary);
  std::stringstream sa, sb;
  sa << a.rdbuf();
  sb << b.rdbuf();
  EXPECT_EQ(sa.str(), sb.str());

  // Shards of another slicing are pass-aligned too: slices 0, 1 of 3 and 4, 5 of 6 mix.
  const fs::path six = scratch("six");
  writeShards(six, 6);
  fs::copy_file(six / farm::shardFileName(4), dir / "shard_99998.exr");
  fs::copy_file(six / farm::shardFileName(5), dir / "shard_99999.exr");
  fs::remove(dir / farm::shardFileName(2));
  const auto set = farm::checkShards(farm::findShards({dir.string()}));
  FloatImage mixed;
  farm::mergeShards(set, [&](int, const FloatImage& image, const std::vector<ExrChannel>&) { mixed = image; });
  EXPECT_TRUE(mixed.rgba == single.color.rgba);
}

TEST_F(FarmRender, MergeRefusesShardsThatDoNotBelongTogether) {
  const fs::path dir = scratch("refuse");
  writeShards(dir, 4);
  auto expectRefusal = [&](const std::string& needle) {
    try {
      farm::checkShards(farm::findShards({dir.string()}));
      ADD_FAILURE() << "merged despite: " << needle;
    } catch (const farm::FarmError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  // Missing: a gap in the middle.
  fs::rename(dir / farm::shardFileName(2), dir / "kept.exr");
  expectRefusal("missing samples [");
  // Overlapping: the same range twice.
  fs::copy_file(dir / farm::shardFileName(1), dir / farm::shardFileName(2));
  expectRefusal("overlaps");
  fs::remove(dir / farm::shardFileName(2));
  fs::rename(dir / "kept.exr", dir / farm::shardFileName(2));
  // Other settings (seed).
  const fs::path other = scratch("other_seed");
  cl_.seed = 6;
  ASSERT_TRUE(renderOverridesFrom(cl_, o_));
  writeShards(other, 4);
  fs::copy_file(other / farm::shardFileName(3), dir / farm::shardFileName(3), fs::copy_options::overwrite_existing);
  expectRefusal("seed: '5' vs '6'");
}

}  // namespace
}  // namespace sdfc
