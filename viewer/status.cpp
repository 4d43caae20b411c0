#include "status.h"

#include <cstdio>

namespace sdfc::view {

std::string titleFor(const Status& s) {
  char text[512];
  std::string title = "sdfc view: " + s.file;
  if (!s.error.empty()) title += " | ERROR: " + s.error + " (see terminal)";
  if (s.compiling) title += " | compiling";
  std::snprintf(text, sizeof text, " | %s%s | %u/%u spp | %.1f spp/s | %.0f ms | %ux%u%s",
                s.view.c_str(), s.denoise ? "+denoise" : "", s.spp, s.target_spp,
                s.spp_per_second, s.frame_ms, s.width, s.height, s.preview ? " (moving)" : "");
  title += text;
  if (s.uses_time) {
    std::snprintf(text, sizeof text, " | t=%.2f%s", s.time, s.playing ? "" : " paused");
    title += text;
  }
  return title;
}

void RateMeter::add(double seconds, uint32_t samples) {
  // Exponential forgetting with about a second of memory.
  const double keep = seconds_ + seconds > 1.0 ? 1.0 / (seconds_ + seconds) : 1.0;
  seconds_ = (seconds_ + seconds) * keep;
  samples_ = (samples_ + samples) * keep;
}

double RateMeter::samplesPerSecond() const { return seconds_ > 0 ? samples_ / seconds_ : 0; }

void RateMeter::reset() { seconds_ = samples_ = 0; }

}  // namespace sdfc::view
