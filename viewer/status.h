// What the title bar says: file, view, samples, samples per second, frame time,
// resolution, and whether the last save had errors.
#pragma once
#include <cstdint>
#include <string>

namespace sdfc::view {

struct Status {
  std::string file;
  std::string view;
  uint32_t spp = 0, target_spp = 0;
  double spp_per_second = 0;
  double frame_ms = 0;
  uint32_t width = 0, height = 0;  // resolution of the image being drawn
  bool preview = false;            // dynamic resolution while moving
  bool denoise = false;
  bool playing = false;
  double time = 0;
  bool uses_time = false;
  bool compiling = false;
  std::string error;  // non-empty: the last save did not compile
};

std::string titleFor(const Status& status);

// Rates over a sliding window of about a second.
class RateMeter {
 public:
  void add(double seconds, uint32_t samples);
  double samplesPerSecond() const;
  void reset();

 private:
  double seconds_ = 0;
  double samples_ = 0;
};

}  // namespace sdfc::view
