// `sdfc merge`: shards -> images (farm/shard_merge.h); refuses shards that do not
// belong together with a message naming the files.
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "commands.h"
#include "cli_support.h"
#include "exr_channels.h"
#include "image_io.h"
#include "progress.h"
#include "render_layers.h"
#include "shard_merge.h"

namespace sdfc {

namespace {

// The files merge would write: each image and, with --png, its PNG.
std::vector<std::string> outputPaths(const CommandLine& cl, const farm::ShardSet& set) {
  std::vector<std::string> paths;
  const bool animation = set.frames.count(farm::kNoFrame) == 0;
  for (const auto& [frame, shards] : set.frames) {
    const std::string path = animation ? farm::framePath(cl.output, frame) : cl.output;
    paths.push_back(path);
    if (cl.png) paths.push_back(path.substr(0, path.find_last_of('.')) + ".png");
  }
  return paths;
}

// An output that is one of the shards (by file identity: another spelling, a
// hard link or a symlink is the same file) would be overwritten while merging.
void refuseOutputOverInput(const CommandLine& cl, const farm::ShardSet& set) {
  for (const std::string& output : outputPaths(cl, set)) {
    std::error_code error;
    if (!std::filesystem::exists(output, error)) continue;
    for (const auto& [frame, shards] : set.frames)
      for (const auto& [path, header] : shards)
        if (std::filesystem::equivalent(output, path, error))
          throw farm::FarmError("the output " + output + " is one of the shards being merged (" + path +
                                "); choose another -o");
  }
}

}  // namespace

int runMerge(const CommandLine& cl) {
  if (!checkImageExtension(cl.output)) return kExitUsage;  // the extension, before any work
  int first = farm::kNoFrame, last = farm::kNoFrame;
  farm::ShardSet set;
  farm::MergeStats stats;
  // Every problem of the shards themselves (missing, not shards, not belonging
  // together, damaged pixels) is bad input: exit 2 with the file named.
  try {
    if (!cl.frames.empty()) std::tie(first, last) = farm::parseFrameRange(cl.frames);
    set = farm::checkShards(farm::findShards(cl.inputs), first, last);
    refuseOutputOverInput(cl, set);
    const bool animation = set.frames.count(farm::kNoFrame) == 0;
    // As render: sdfc creates no folders (a mistyped -o would leave them behind).
    for (const std::string& path : outputPaths(cl, set)) checkWritablePath(path);
    const bool layers = set.reference.layers;
    if (layers && imageFormatFromPath(cl.output) != ImageFormat::Exr)
      throw farm::FarmError("the shards are of a --layers render, which merges into one multi-channel EXR: -o '" +
                            cl.output + "' must end in .exr");
    stats = farm::mergeShards(set, [&](int frame, const FloatImage& merged,
                                       const std::vector<ExrChannel>& features) {
      const std::string path = animation ? farm::framePath(cl.output, frame) : cl.output;
      FloatImage image = merged;
      if (layers) {
        // The file `render --layers` writes: the samples' channels from the sums,
        // the centre ray's from the shard holding sample 0 (docs/layers.md).
        std::vector<ExrChannel> channels = layerSampleChannels(merged, set.reference.spp);
        for (const char* name : kLayerRayChannelNames) {
          const auto it = std::find_if(features.begin(), features.end(),
                                       [&](const ExrChannel& c) { return c.name == name; });
          if (it == features.end())
            throw farm::FarmError(std::string("a --layers shard holding sample 0 of ") +
                                  (animation ? "frame " + std::to_string(frame) : std::string("the still")) +
                                  " has no '" + name + "' channel (damaged, or not written by sdfc)");
          channels.push_back(*it);
        }
        writeExrChannels(path, merged.width, merged.height, std::move(channels));
        for (size_t p = 0; p < size_t(image.width) * image.height; ++p) image.rgba[p * 4 + 3] = 1.0f;
      } else {
        writeImage(path, image);
      }
      if (cl.png) {
        const std::string png = path.substr(0, path.find_last_of('.')) + ".png";
        if (png != path) writeImage(png, image);
      }
    });
  } catch (const farm::FarmError& e) {
    std::cerr << "sdfc: error: merge: " << e.what() << "\n";
    return kExitUsage;
  }
  if (!cl.quiet)
    std::cerr << "sdfc: merged " << stats.shards << " shards into " << stats.frames
              << (stats.frames == 1 ? " image" : " frames") << " (" << set.reference.width << "x"
              << set.reference.height << ", " << set.reference.spp << " spp) in " << formatSeconds(stats.seconds)
              << "\n";
  return kExitOk;
}

}  // namespace sdfc
