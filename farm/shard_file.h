// A shard on disk: a linear EXR holding one sample range of one image.
//
// Channels R, G, B (float) are the shard's own mean radiance, so any EXR viewer
// shows it; sum.{R,G,B}.{0..3} (uint) are the exact fixed-point sums of its samples
// (runtime/sample_sum.h, 128 bits as four 32-bit words, least significant first),
// which `sdfc merge` adds. A shard of a `--layers` render also holds
// sum.Y2.{0..3}, the sum of its samples' squared luminance (the variance layer's
// input), and the shard holding sample 0 of its image holds the layers that come
// from the unjittered centre ray, not from samples (albedo.*, N.*, Z, material,
// object: float, under their names in the layered EXR). String attributes
// "sdfc.*" record everything a merge must agree on (ShardHeader).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "exr_channels.h"
#include "sample_sum.h"
#include "shard_plan.h"

namespace sdfc::farm {

// sdfc.format: 2 added the layers (sdfc.layers, sum.Y2, the centre ray's layers).
// A file without it, or of another format, is refused by name: never guessed at.
constexpr uint32_t kShardFormat = 2;

struct ShardHeader {
  std::string scene_hash;   // source text, -D values and compile flags
  std::string kernel_hash;  // the SPIR-V the shard ran
  std::string version;      // sdfc version
  std::string device;       // Vulkan device name
  std::string driver;       // driver name and version
  std::string settings;     // canonical render settings (size, spp, bounces, ...)
  uint32_t width = 0, height = 0;
  uint32_t seed = 0;
  uint32_t spp = 0;               // of the whole image
  uint32_t samples_per_pass = 0;  // pass split shared by every shard
  uint32_t slices = 1;            // shards per image
  uint32_t slice = 0;
  int frame = kNoFrame;
  double time = 0;                // scene time of the frame
  SampleRange samples;
  bool layers = false;            // a `render --layers` shard (sdfc.layers)

  // Not in the file: the file this was read from (st_dev, st_ino, size,
  // mtime), so that merge knows the pixels it adds are from the same file
  // whose header it checked (a resubmitted job may replace a shard between).
  struct Stamp {
    uint64_t device = 0, inode = 0, size = 0;
    int64_t mtime_ns = 0;
    bool operator==(const Stamp&) const = default;
  } stamp;

  // Sums per pixel: r, g, b, and with layers the squared luminance.
  uint32_t sumsPerPixel() const { return layers ? 4 : 3; }
};

// Attributes two shards of one job must agree on (all but the slicing, range, frame
// and time: shards of different slice counts still merge exactly, being pass-aligned).
// Returns "" when they do, otherwise "field: 'a' vs 'b'".
std::string headerMismatch(const ShardHeader& a, const ShardHeader& b);

struct ShardImage {
  ShardHeader header;
  std::vector<SampleSum> sums;  // header.sumsPerPixel() per pixel, row-major
  // Float channels besides the shard's own mean (the centre ray's layers).
  std::vector<ExrChannel> features;
};

// Writes through "<path>.tmp" and a rename: a killed shard leaves no shard file.
void writeShard(const std::string& path, const ShardImage& shard);
// Why `path` is no file to read a shard from ("" when it may be read), in
// words: missing, a link to nothing or one that loops, a directory, a FIFO...
std::string notAShard(const std::string& path);
// Throws FarmError naming the file when it is not a readable sdfc shard.
ShardHeader readShardHeader(const std::string& path);
ShardImage readShard(const std::string& path);
// Adds the shard's sums to `total` (two's complement, modulo 2^128: exact while the
// true sum fits a SampleSum) without keeping a copy; returns its header. With
// `features`, also returns its float channels other than R, G, B there.
// With `checked` (the header checkShards read), the file must still be the one
// read then, with the same header: FarmError otherwise, before anything is added.
// The header and the pixels come from one read of the file.
ShardHeader addShard(const std::string& path, std::vector<unsigned __int128>& total,
                     std::vector<ExrChannel>* features = nullptr, const ShardHeader* checked = nullptr);

// 16 hex digits of FNV-1a 64 (a fingerprint, not a security measure).
std::string fingerprint(const void* data, size_t size);

}  // namespace sdfc::farm
