#include "shard_merge.h"

#include <algorithm>
#include <chrono>
#include <filesystem>

namespace sdfc::farm {
namespace fs = std::filesystem;

std::vector<std::string> findShards(const std::vector<std::string>& inputs) {
  std::vector<std::string> paths;
  for (const std::string& input : inputs) {
    // Every look at the file system reports in our words, naming the path (a
    // link that loops once printed the library's "Too many levels of symbolic
    // links" and exited 4).
    std::error_code error;
    if (!fs::is_directory(fs::status(input, error))) {
      paths.push_back(input);  // readShardHeader says what is wrong with it
      continue;
    }
    std::vector<std::string> found;
    fs::directory_iterator it(input, error);
    if (error) throw FarmError(input + ": cannot list this directory (" + error.message() + ")");
    for (; it != fs::directory_iterator(); it.increment(error)) {
      const fs::directory_entry& entry = *it;
      const std::string name = entry.path().filename().string();
      if (name.rfind("shard_", 0) != 0 || entry.path().extension() != ".exr") continue;
      // A shard's name on something that is no regular file (a folder, a
      // link to nothing or to itself) is a damaged shard, refused by name.
      std::error_code entry_error;
      if (!entry.is_regular_file(entry_error)) throw FarmError(entry.path().string() + ": " + notAShard(entry.path().string()));
      found.push_back(entry.path().string());
    }
    if (error) throw FarmError(input + ": cannot list this directory (" + error.message() + ")");
    if (found.empty()) throw FarmError(input + ": no shard_*.exr files in this directory");
    std::sort(found.begin(), found.end());
    paths.insert(paths.end(), found.begin(), found.end());
  }
  if (paths.empty()) throw FarmError("no shards to merge");
  return paths;
}

namespace {
std::string frameName(int frame) { return frame == kNoFrame ? "the still" : "frame " + std::to_string(frame); }
std::string rangeText(const SampleRange& r) {
  return "[" + std::to_string(r.begin) + ", " + std::to_string(r.end) + ")";
}
}  // namespace

ShardSet checkShards(const std::vector<std::string>& paths, int first_frame, int last_frame) {
  ShardSet set;
  std::string reference_path;
  for (const std::string& path : paths) {
    const ShardHeader h = readShardHeader(path);
    if (reference_path.empty()) {
      set.reference = h;
      reference_path = path;
    } else if (h.layers != set.reference.layers) {
      const std::string& layered = h.layers ? path : reference_path;
      const std::string& plain = h.layers ? reference_path : path;
      throw FarmError(path + " does not belong with " + reference_path + ": " + layered +
                      " is a shard of a --layers render and " + plain +
                      " is not (render every shard with --layers, or none)");
    } else if (const std::string why = headerMismatch(set.reference, h); !why.empty()) {
      throw FarmError(path + " does not belong with " + reference_path + ": " + why);
    }
    if (h.samples_per_pass == 0 || h.samples.begin % h.samples_per_pass != 0 ||
        (h.samples.end % h.samples_per_pass != 0 && h.samples.end != h.spp))
      throw FarmError(path + ": sample range " + rangeText(h.samples) + " is not on passes of " +
                      std::to_string(h.samples_per_pass) + " samples");
    set.frames[h.frame].push_back({path, h});
  }
  if (set.frames.count(kNoFrame) && set.frames.size() > 1)
    throw FarmError("a still's shards are mixed with an animation's (" + set.frames.at(kNoFrame)[0].first + ")");
  if (first_frame != kNoFrame)
    for (int f = first_frame; f <= last_frame; ++f)
      if (!set.frames.count(f)) throw FarmError("missing all shards of frame " + std::to_string(f));
  for (auto& [frame, shards] : set.frames) {
    std::sort(shards.begin(), shards.end(), [](const auto& a, const auto& b) {
      return a.second.samples.begin != b.second.samples.begin ? a.second.samples.begin < b.second.samples.begin
                                                              : a.second.samples.end < b.second.samples.end;
    });
    uint32_t covered = 0;
    for (size_t i = 0; i < shards.size(); ++i) {
      if (shards[i].second.time != shards[0].second.time)
        throw FarmError(shards[i].first + " renders " + frameName(frame) + " at time " +
                        std::to_string(shards[i].second.time) + ", " + shards[0].first + " at " +
                        std::to_string(shards[0].second.time));
      const SampleRange& r = shards[i].second.samples;
      if (r.begin < covered)
        throw FarmError(shards[i].first + " overlaps " + shards[i - 1].first + " in " + frameName(frame) +
                        ": samples " + rangeText(r) + " and " + rangeText(shards[i - 1].second.samples));
      if (r.begin > covered)
        throw FarmError("missing samples " + rangeText({covered, r.begin}) + " of " + frameName(frame) +
                        " (before " + shards[i].first + ")");
      covered = r.end;
    }
    if (covered != set.reference.spp)
      throw FarmError("missing samples " + rangeText({covered, set.reference.spp}) + " of " + frameName(frame) +
                      " (after " + shards.back().first + ")");
  }
  return set;
}

MergeStats mergeShards(const ShardSet& set,
                       const std::function<void(int frame, const FloatImage& image,
                                                const std::vector<ExrChannel>& features)>& emit) {
  const auto start = std::chrono::steady_clock::now();
  MergeStats stats;
  const ShardHeader& h = set.reference;
  const size_t pixels = size_t(h.width) * h.height;
  const uint32_t stride = h.sumsPerPixel();
  std::vector<unsigned __int128> total;
  std::vector<ExrChannel> features;
  for (const auto& [frame, shards] : set.frames) {
    total.assign(pixels * stride, 0);
    features.clear();
    for (const auto& [path, header] : shards) {
      // The centre ray's layers do not depend on the samples; a single render
      // reads them in its last pass, the shard holding sample 0 in its own.
      const bool first = h.layers && header.samples.begin == 0;
      addShard(path, total, first ? &features : nullptr, &header);
      if (first && features.empty())
        throw FarmError(path + ": a --layers shard holding sample 0 without the albedo, N, Z, material "
                        "and object channels (damaged, or not written by sdfc)");
      ++stats.shards;
    }
    FloatImage image(h.width, h.height, 1.0f);
    for (size_t p = 0; p < pixels; ++p)
      for (uint32_t c = 0; c < stride; ++c)
        image.rgba[p * 4 + c] = sampleMean(static_cast<SampleSum>(total[p * stride + c]), h.spp);
    emit(frame, image, features);
    ++stats.frames;
  }
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

}  // namespace sdfc::farm
