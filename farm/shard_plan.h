// How a render is cut into shards: the engine-neutral part of a farm job.
//
// A job renders one still or the frames first..last; each image's sample
// sequence [0, spp) is cut into `slices` ranges on pass boundaries (the renderer
// draws samples_per_pass samples per pass, and a pass's float mean depends on
// which samples it holds, so a slice that started mid-pass would not reproduce a
// single-process render's bits). Task t of taskCount() renders frame t / slices,
// slice t % slices: a Slurm array index or a Kubernetes JOB_COMPLETION_INDEX.
#pragma once
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace sdfc::farm {

// A farm-level problem with a user-facing message (bad plan, mismatched shards).
class FarmError : public std::runtime_error {
 public:
  explicit FarmError(const std::string& message) : std::runtime_error(message) {}
};

struct SampleRange {
  uint32_t begin = 0, end = 0;  // [begin, end)
  uint32_t count() const { return end - begin; }
};

// How `spp` samples fall into passes of at most `samples_per_pass`, as the
// renderer draws them: "4 passes of 8 samples", "2 passes (18 + 14 samples)",
// "6 passes (5 of 18 samples and a last of 10)".
std::string passesText(uint32_t spp, uint32_t samples_per_pass);

// `slices` contiguous ranges covering [0, spp), each a whole number of passes of
// samples_per_pass (the last pass of the image may be short), sizes differing by at
// most one pass. Throws FarmError when there are fewer passes than slices.
std::vector<SampleRange> splitSamples(uint32_t spp, uint32_t samples_per_pass, uint32_t slices);

constexpr int kNoFrame = -1;  // a still

struct ShardTask {
  int frame = kNoFrame;
  uint32_t slice = 0;
  SampleRange samples;
};

struct ShardPlan {
  uint32_t spp = 0;
  uint32_t samples_per_pass = 1;
  uint32_t slices = 1;      // shards per image
  int first_frame = kNoFrame, last_frame = kNoFrame;  // kNoFrame: a still
  double fps = 24;

  bool animation() const { return first_frame != kNoFrame; }
  uint32_t frameCount() const { return animation() ? uint32_t(last_frame - first_frame + 1) : 1; }
  uint32_t taskCount() const { return frameCount() * slices; }
  ShardTask task(uint32_t index) const;  // throws FarmError when out of range
  double frameTime(int frame) const { return frame / fps; }
};

// "shard_00042.exr": the file task `index` writes into the shard directory.
std::string shardFileName(uint32_t index);

// "out.png" + frame 7 -> "out_0007.png" (the frame sequence naming of `sdfc render`).
std::string framePath(const std::string& path, int frame);

// "A-B" with integers 0 <= A <= B -> (A, B); throws FarmError otherwise.
std::pair<int, int> parseFrameRange(const std::string& text);

}  // namespace sdfc::farm
