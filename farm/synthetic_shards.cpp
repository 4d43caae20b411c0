// farm_synthetic_shards DIR WIDTH HEIGHT SHARDS: writes SHARDS shards of one
// WIDTHxHEIGHT still (one sample each, passes of one sample) through the real
// shard writer, with pseudo-random radiance, for measuring `sdfc merge`'s time and
// memory at sizes too slow to render here (bench/farm_bench.py). Prints the median
// write time per shard in ms.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "shard_file.h"

int main(int argc, char** argv) {
  using namespace sdfc;
  if (argc != 5) {
    std::fprintf(stderr, "usage: farm_synthetic_shards DIR WIDTH HEIGHT SHARDS\n");
    return 2;
  }
  const std::string dir = argv[1];
  const uint32_t width = uint32_t(std::atoi(argv[2])), height = uint32_t(std::atoi(argv[3]));
  const uint32_t shards = uint32_t(std::atoi(argv[4]));
  std::filesystem::create_directories(dir);
  farm::ShardImage shard;
  farm::ShardHeader& h = shard.header;
  h.scene_hash = "synthetic";
  h.kernel_hash = "synthetic";
  h.version = "synthetic";
  h.device = "none";
  h.driver = "none";
  h.settings = std::to_string(width) + "x" + std::to_string(height) + " synthetic";
  h.width = width;
  h.height = height;
  h.spp = shards;
  h.samples_per_pass = 1;
  h.slices = shards;
  shard.sums.resize(size_t(width) * height * 3);
  uint64_t state = 88172645463325252ull;
  std::vector<double> times;
  for (uint32_t k = 0; k < shards; ++k) {
    h.slice = k;
    h.samples = {k, k + 1};
    for (SampleSum& s : shard.sums) {
      state ^= state << 13;
      state ^= state >> 7;
      state ^= state << 17;
      // One sample's radiance in [0, 2), as the renderer's sampleTerm stores it.
      s = sampleTerm(float(double(state >> 11) * 0x1.0p-52), 1);
    }
    char name[32];
    std::snprintf(name, sizeof name, "/shard_%05u.exr", k);
    const auto start = std::chrono::steady_clock::now();
    farm::writeShard(dir + name, shard);
    times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() * 1000);
  }
  std::sort(times.begin(), times.end());
  std::printf("%.1f\n", times[times.size() / 2]);
  return 0;
}
