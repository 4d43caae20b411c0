#include "shard_plan.h"

#include <algorithm>
#include <cstdio>

namespace sdfc::farm {

std::string passesText(uint32_t spp, uint32_t samples_per_pass) {
  const uint64_t per = std::max<uint32_t>(samples_per_pass, 1);
  const uint64_t passes = (uint64_t(spp) + per - 1) / per;
  const uint64_t last = spp - (passes - 1) * per;
  const std::string n = std::to_string(passes) + (passes == 1 ? " pass" : " passes");
  if (last == per) return n + " of " + std::to_string(per) + " samples";
  // The last pass is short: 32 spp at 18 a pass are 18 + 14, not "2 of 18".
  if (passes == 2) return n + " (" + std::to_string(per) + " + " + std::to_string(last) + " samples)";
  return n + " (" + std::to_string(passes - 1) + " of " + std::to_string(per) + " samples and a last of " +
         std::to_string(last) + ")";
}

std::vector<SampleRange> splitSamples(uint32_t spp, uint32_t samples_per_pass, uint32_t slices) {
  if (spp == 0 || samples_per_pass == 0 || slices == 0)
    throw FarmError("spp, samples per pass and shards must be positive");
  const uint64_t passes = (uint64_t(spp) + samples_per_pass - 1) / samples_per_pass;
  if (slices > passes)
    throw FarmError(std::to_string(spp) + " spp are " + passesText(spp, samples_per_pass) +
                    "; a shard takes whole passes, so use at most " + std::to_string(passes) +
                    " shards per image (or more spp)");
  std::vector<SampleRange> ranges(slices);
  for (uint32_t k = 0; k < slices; ++k) {
    const uint64_t first_pass = passes * k / slices, end_pass = passes * (k + 1) / slices;
    ranges[k].begin = uint32_t(first_pass * samples_per_pass);
    ranges[k].end = uint32_t(std::min<uint64_t>(end_pass * samples_per_pass, spp));
  }
  return ranges;
}

ShardTask ShardPlan::task(uint32_t index) const {
  if (index >= taskCount())
    throw FarmError("shard index " + std::to_string(index) + " is out of range: this job has " +
                    std::to_string(taskCount()) + " shards (0.." + std::to_string(taskCount() - 1) + ")");
  ShardTask t;
  t.slice = index % slices;
  t.frame = animation() ? first_frame + int(index / slices) : kNoFrame;
  t.samples = splitSamples(spp, samples_per_pass, slices)[t.slice];
  return t;
}

std::string shardFileName(uint32_t index) {
  char name[32];
  std::snprintf(name, sizeof name, "shard_%05u.exr", index);
  return name;
}

std::string framePath(const std::string& path, int frame) {
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.find_last_of('.');
  char number[16];
  std::snprintf(number, sizeof number, "_%04d", frame);
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return path + number;
  return path.substr(0, dot) + number + path.substr(dot);
}

std::pair<int, int> parseFrameRange(const std::string& text) {
  // (\d{1,6})-(\d{1,6}), scanned by hand (std::regex recurses per character).
  const size_t dash = text.find('-');
  auto whole = [](const std::string& s) {
    return !s.empty() && s.size() <= 6 && s.find_first_not_of("0123456789") == std::string::npos;
  };
  const std::string a = dash == std::string::npos ? "" : text.substr(0, dash);
  const std::string b = dash == std::string::npos ? "" : text.substr(dash + 1);
  if (!whole(a) || !whole(b) || std::stoi(a) > std::stoi(b))
    throw FarmError("--frames expects A-B, frame numbers with A <= B, e.g. 0-239");
  return {std::stoi(a), std::stoi(b)};
}

}  // namespace sdfc::farm
