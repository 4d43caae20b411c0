#include "progress.h"

#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <memory>
#include <string>

namespace sdfc {
namespace {

std::atomic<bool> g_interrupted{false};
static_assert(std::atomic<bool>::is_always_lock_free, "flag is set from a signal handler");

extern "C" void onInterruptSignal(int signal_number) {
  g_interrupted.store(true);
  std::signal(signal_number, SIG_DFL);  // a second Ctrl-C terminates
}

}  // namespace

std::string formatSeconds(double seconds) {
  char buffer[64];
  if (seconds < 0) return "?";
  if (seconds < 60) {
    std::snprintf(buffer, sizeof buffer, "%.1fs", seconds);
  } else if (seconds < 3600) {
    const int s = static_cast<int>(seconds + 0.5);
    std::snprintf(buffer, sizeof buffer, "%dm %02ds", s / 60, s % 60);
  } else {
    const int s = static_cast<int>(seconds + 0.5);
    std::snprintf(buffer, sizeof buffer, "%dh %02dm", s / 3600, (s / 60) % 60);
  }
  return buffer;
}

ProgressCallback makeTerminalProgress(const char* label) {
  const bool tty = isatty(STDERR_FILENO) != 0;
  auto last_line = std::make_shared<double>(-1e9);
  std::string name = label ? label : "render";
  return [tty, last_line, name](const ProgressInfo& info) {
    const double fraction =
        info.samples_total ? double(info.samples_done) / info.samples_total : 1.0;
    if (tty) {
      constexpr int kBarWidth = 30;
      const int filled = static_cast<int>(fraction * kBarWidth + 0.5);
      std::string bar(filled, '#');
      bar.resize(kBarWidth, '.');
      std::fprintf(stderr, "\r%s [%s] %3d%% %u/%u spp  %s elapsed  ETA %s\x1b[K", name.c_str(),
                   bar.c_str(), static_cast<int>(fraction * 100 + 0.5), info.samples_done,
                   info.samples_total, formatSeconds(info.elapsed_seconds).c_str(),
                   info.finished ? "0.0s" : formatSeconds(info.eta_seconds).c_str());
      if (info.finished) std::fputc('\n', stderr);
      std::fflush(stderr);
      return;
    }
    // Logs: rate-limit to one line a second so big renders do not flood them.
    if (!info.finished && info.elapsed_seconds - *last_line < 1.0) return;
    *last_line = info.elapsed_seconds;
    std::fprintf(stderr, "%s: %u/%u spp (%d%%), %s elapsed, ETA %s\n", name.c_str(),
                 info.samples_done, info.samples_total, static_cast<int>(fraction * 100 + 0.5),
                 formatSeconds(info.elapsed_seconds).c_str(),
                 info.finished ? "0.0s" : formatSeconds(info.eta_seconds).c_str());
  };
}

std::atomic<bool>& interruptFlag() { return g_interrupted; }

const std::atomic<bool>* installInterruptHandler() {
  g_interrupted.store(false);
  std::signal(SIGINT, onInterruptSignal);
  std::signal(SIGTERM, onInterruptSignal);
  return &g_interrupted;
}

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void reportFinished(const ProgressCallback& progress, uint32_t samples_done, uint32_t samples_total,
                    uint32_t passes_done, double elapsed_seconds) {
  if (!progress) return;
  ProgressInfo info;
  info.samples_done = samples_done;
  info.samples_total = samples_total;
  info.passes_done = passes_done;
  info.elapsed_seconds = elapsed_seconds;
  info.eta_seconds = 0;
  info.finished = true;
  progress(info);
}

}  // namespace sdfc
