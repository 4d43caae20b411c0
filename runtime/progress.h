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
  // The share of the whole job done (JobProgress: the samples and the denoise
  // after them); < 0: samples_done / samples_total.
  double fraction = -1;
  const char* stage = nullptr;  // what runs after the samples ("denoising"); null while sampling
};

// Called by the renderer after every pass, on the rendering thread.
using ProgressCallback = std::function<void(const ProgressInfo&)>;

// Wall seconds since `start` (steady clock).
double secondsSince(std::chrono::steady_clock::time_point start);

// The last call of a render (finished, ETA 0); nothing when `progress` is empty.
void reportFinished(const ProgressCallback& progress, uint32_t samples_done, uint32_t samples_total,
                    uint32_t passes_done, double elapsed_seconds);

// One bar over a whole image: its samples, however many renders draw them
// (renderHalves' two halves, adaptive sampling's phases, each reporting its own
// counts and its own end), then the denoise; the ETA counts the denoise's
// predicted time until the denoiser reports its own progress. Forwards to
// `out` a fraction that never falls, and one finished call, from finish().
class JobProgress {
 public:
  JobProgress(ProgressCallback out, uint32_t samples_total, double denoise_seconds);
  // For the renderers (renderer.render, renderHalves, renderAdaptive).
  ProgressCallback samples();
  // The denoise (`stage`, e.g. "denoising") starts, then is `share` done (0..1).
  void startStage(const char* stage);
  void stageProgress(double share);
  // The last call: 100% unless interrupted.
  void finish(uint32_t samples_done, uint32_t passes, bool interrupted);

 private:
  void send(ProgressInfo info, double fraction);
  ProgressCallback out_;
  uint32_t total_ = 0, base_ = 0, done_ = 0, passes_ = 0, base_passes_ = 0;
  double predicted_ = 0, sampling_seconds_ = -1, stage_start_ = 0, last_fraction_ = 0;
  const char* stage_ = nullptr;
  std::chrono::steady_clock::time_point start_;
};

// A progress reporter on stderr: a redrawn bar with ETA when stderr is a
// terminal, otherwise one plain line per pass (at most ~1 per second, plus the last).
ProgressCallback makeTerminalProgress(const char* label = "render");

// "1m 05s", "3.2s".
std::string formatSeconds(double seconds);

// Installs a SIGINT (and SIGTERM) handler that sets the returned flag; the
// renderer stops after its current pass, the nlm/nlr denoiser between blocks of
// pixels. A second Ctrl-C kills the process as usual (the handler restores the
// default action on the first signal). With `exit_until_samples`, a signal
// before noteSamplesTaken() (or after noteNothingToSave()) ends the process at
// once instead, exit 130 and nothing written: no sample would be lost, and the
// driver's kernel compile (seconds, in one call) never looks at the flag.
const std::atomic<bool>* installInterruptHandler(bool exit_until_samples = false);
// Samples worth writing exist from now on: a signal sets the flag.
void noteSamplesTaken();
// None again (a new frame starts): a signal ends the process, if installed so.
void noteNothingToSave();

// The flag installInterruptHandler() sets (also usable without installing).
std::atomic<bool>& interruptFlag();

}  // namespace sdfc
