// `sdfc merge`: shards -> images, exactly.
//
// The shards' headers are checked first (same scene, kernel, version, device,
// settings and seed; per frame, sample ranges that tile [0, spp) on pass boundaries
// with no overlap and no gap), then each frame's shards are read one at a time and
// their integer sums added: the image equals a single-process render bit for bit.
#pragma once
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "float_image.h"
#include "shard_file.h"

namespace sdfc::farm {

// The shard files of `inputs`: files as given, directories scanned for shard_*.exr.
std::vector<std::string> findShards(const std::vector<std::string>& inputs);

// Frame (kNoFrame for a still) -> its shards' headers and paths, sorted by range.
struct ShardSet {
  ShardHeader reference;
  std::map<int, std::vector<std::pair<std::string, ShardHeader>>> frames;
};

// Reads every header and checks that they belong together; throws FarmError with
// a message naming the files otherwise. With required frames (first <= last), each
// of them must be present; kNoFrame (a still) must be the only frame when present.
ShardSet checkShards(const std::vector<std::string>& paths, int first_frame = kNoFrame,
                     int last_frame = kNoFrame);

struct MergeStats {
  size_t shards = 0;
  size_t frames = 0;
  double seconds = 0;
};

// Merges each frame of `set` in frame order and hands its image (linear; a = 1, or
// with layers the mean squared luminance) and, with layers, the centre ray's
// layers of the shard holding sample 0 to `emit`. Holds one frame's sums (48
// bytes a pixel, 64 with layers) and one shard at a time.
MergeStats mergeShards(const ShardSet& set,
                       const std::function<void(int frame, const FloatImage& image,
                                                const std::vector<ExrChannel>& features)>& emit);

}  // namespace sdfc::farm
