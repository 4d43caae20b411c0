// `sdfc merge`: shards -> images (farm/shard_merge.h); refuses shards that do not
// belong together with a message naming the files.
#include <filesystem>
#include <iostream>

#include "commands.h"
#include "cli_support.h"
#include "image_io.h"
#include "progress.h"
#include "shard_merge.h"

namespace sdfc {

int runMerge(const CommandLine& cl) {
  if (!checkImageExtension(cl.output)) return kExitUsage;  // the extension, before any work
  int first = farm::kNoFrame, last = farm::kNoFrame;
  farm::ShardSet set;
  try {
    if (!cl.frames.empty()) std::tie(first, last) = farm::parseFrameRange(cl.frames);
    set = farm::checkShards(farm::findShards(cl.inputs), first, last);
  } catch (const farm::FarmError& e) {
    std::cerr << "sdfc: error: merge: " << e.what() << "\n";
    return kExitUsage;
  }
  const bool animation = set.frames.count(farm::kNoFrame) == 0;
  const std::filesystem::path parent = std::filesystem::path(cl.output).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  const farm::MergeStats stats = farm::mergeShards(set, [&](int frame, const FloatImage& image) {
    const std::string path = animation ? farm::framePath(cl.output, frame) : cl.output;
    writeImage(path, image);
    if (cl.png) {
      const std::string png = path.substr(0, path.find_last_of('.')) + ".png";
      if (png != path) writeImage(png, image);
    }
  });
  if (!cl.quiet)
    std::cerr << "sdfc: merged " << stats.shards << " shards into " << stats.frames
              << (stats.frames == 1 ? " image" : " frames") << " (" << set.reference.width << "x"
              << set.reference.height << ", " << set.reference.spp << " spp) in " << formatSeconds(stats.seconds)
              << "\n";
  return kExitOk;
}

}  // namespace sdfc
