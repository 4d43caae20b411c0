// Render progress reporting and Ctrl-C handling.
#pragma once
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <string>

namespace sdfc {

struct ProgressInfo {
  uint32_t samples_done = 0;
  uint32_t samples_total = 0;
  uint32_t passes_done = 0;
  double elapsed_seconds = 0;
  double eta_seconds = -1;  // < 0 while unknown
  bool finished = false;    // last call of a render (complete or interrupted)
};

// Called by the renderer after every pass, on the rendering thread.
using ProgressCallback = std::function<void(const ProgressInfo&)>;

// Wall seconds since `start` (steady clock).
double secondsSince(std::chrono::steady_clock::time_point start);

// The last call of a render (finished, ETA 0); nothing when `progress` is empty.
void reportFinished(const ProgressCallback& progress, uint32_t samples_done, uint32_t samples_total,
                    uint32_t passes_done, double elapsed_seconds);

// A progress reporter on stderr: a redrawn bar with ETA when stderr is a
// terminal, otherwise one plain line per pass (at most ~1 per second, plus the last).
ProgressCallback makeTerminalProgress(const char* label = "render");

// "1m 05s", "3.2s".
std::string formatSeconds(double seconds);

// Installs a SIGINT (and SIGTERM) handler that sets the returned flag; the
// renderer stops after its current pass. A second Ctrl-C kills the process
// as usual (the handler restores the default action on the first signal).
const std::atomic<bool>* installInterruptHandler();

// The flag installInterruptHandler() sets (also usable without installing).
std::atomic<bool>& interruptFlag();

}  // namespace sdfc
