#include "progress.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <memory>
#include <string>

namespace sdfc {
namespace {

std::atomic<bool> g_interrupted{false};
static_assert(std::atomic<bool>::is_always_lock_free, "flags are read and set in a signal handler");

// Whether a signal now ends the process (installInterruptHandler's exit_until_samples).
std::atomic<bool> g_exit_at_once{false};
bool g_exit_until_samples = false;

extern "C" void onInterruptSignal(int signal_number) {
  if (g_exit_at_once.load()) {
    // Async-signal-safe: write(2) and _exit(2) only.
    static const char message[] = "\nsdfc: interrupted before any sample; nothing written\n";
    ssize_t ignored = write(STDERR_FILENO, message, sizeof message - 1);
    (void)ignored;
    _exit(130);
  }
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
  struct State {
    double last_line = -1e9;
    const char* last_stage = nullptr;
  };
  auto state = std::make_shared<State>();
  std::string name = label ? label : "render";
  return [tty, state, name](const ProgressInfo& info) {
    double fraction = info.fraction >= 0 ? info.fraction
                      : info.samples_total ? double(info.samples_done) / info.samples_total
                                           : 1.0;
    fraction = std::clamp(fraction, 0.0, 1.0);
    // 100% is the end's alone: a job 99.6% done shows 99%.
    const int percent = info.finished && fraction >= 1.0 ? 100 : std::min(99, int(fraction * 100));
    const std::string eta = info.finished ? "0.0s" : formatSeconds(info.eta_seconds);
    const std::string stage = info.stage && !info.finished ? std::string(", ") + info.stage : "";
    if (tty) {
      constexpr int kBarWidth = 30;
      const int filled = static_cast<int>(fraction * kBarWidth + 0.5);
      std::string bar(filled, '#');
      bar.resize(kBarWidth, '.');
      std::fprintf(stderr, "\r%s [%s] %3d%% %u/%u spp%s  %s elapsed  ETA %s\x1b[K", name.c_str(),
                   bar.c_str(), percent, info.samples_done, info.samples_total, stage.c_str(),
                   formatSeconds(info.elapsed_seconds).c_str(), eta.c_str());
      if (info.finished) std::fputc('\n', stderr);
      std::fflush(stderr);
      return;
    }
    // Logs: rate-limit to one line a second so big renders do not flood them;
    // a new stage and the last call always get theirs.
    const bool new_stage = info.stage != state->last_stage;
    state->last_stage = info.stage;
    if (!info.finished && !new_stage && info.elapsed_seconds - state->last_line < 1.0) return;
    state->last_line = info.elapsed_seconds;
    std::fprintf(stderr, "%s: %u/%u spp%s (%d%%), %s elapsed, ETA %s\n", name.c_str(), info.samples_done,
                 info.samples_total, stage.c_str(), percent, formatSeconds(info.elapsed_seconds).c_str(),
                 eta.c_str());
  };
}

JobProgress::JobProgress(ProgressCallback out, uint32_t samples_total, double denoise_seconds)
    : out_(std::move(out)), total_(samples_total), predicted_(std::max(0.0, denoise_seconds)),
      start_(std::chrono::steady_clock::now()) {}

void JobProgress::send(ProgressInfo info, double fraction) {
  if (!out_) return;
  last_fraction_ = std::max(last_fraction_, std::clamp(fraction, 0.0, 1.0));
  info.fraction = last_fraction_;
  info.samples_total = total_;
  info.stage = stage_;
  info.elapsed_seconds = secondsSince(start_);
  out_(info);
}

ProgressCallback JobProgress::samples() {
  return [this](const ProgressInfo& in) {
    // A render of part of the samples (a half) counts after those before it; one
    // of all of them (adaptive sampling's rounds) counts alone.
    const bool part = in.samples_total != total_;
    done_ = std::min(total_, part ? base_ + in.samples_done : in.samples_done);
    passes_ = part ? base_passes_ + in.passes_done : in.passes_done;
    if (in.finished) {
      if (!part) return;  // finish() sends the one last call
      base_ += in.samples_done;
      base_passes_ += in.passes_done;
    }
    const double elapsed = secondsSince(start_);
    ProgressInfo info;
    info.samples_done = done_;
    info.passes_done = passes_;
    info.eta_seconds = done_ > 0 ? elapsed / done_ * (total_ - done_) + predicted_ : -1;
    send(info, info.eta_seconds >= 0 ? elapsed / (elapsed + info.eta_seconds) : 0.0);
  };
}

void JobProgress::startStage(const char* stage) {
  sampling_seconds_ = secondsSince(start_);
  stage_start_ = sampling_seconds_;
  stage_ = stage;
  ProgressInfo info;
  info.samples_done = done_;
  info.passes_done = passes_;
  info.eta_seconds = predicted_;
  send(info, sampling_seconds_ / (sampling_seconds_ + predicted_ + 1e-9));
}

void JobProgress::stageProgress(double share) {
  if (sampling_seconds_ < 0) return;
  const double spent = secondsSince(start_) - stage_start_;
  // The prediction, then more and more the stage's own rate (alone from a sixth done).
  double whole = std::max(predicted_, spent);
  if (share > 0.0) {
    const double trust = std::min(1.0, 6.0 * share);
    whole = std::max(spent, (1.0 - trust) * whole + trust * spent / share);
  }
  ProgressInfo info;
  info.samples_done = done_;
  info.passes_done = passes_;
  info.eta_seconds = std::max(0.0, whole - spent);
  send(info, (sampling_seconds_ + spent) / (sampling_seconds_ + whole + 1e-9));
}

void JobProgress::finish(uint32_t samples_done, uint32_t passes, bool interrupted) {
  if (!out_) return;
  ProgressInfo info;
  info.samples_done = samples_done;
  info.passes_done = passes;
  info.eta_seconds = 0;
  info.finished = true;
  stage_ = nullptr;
  send(info, interrupted ? last_fraction_ : 1.0);
}

std::atomic<bool>& interruptFlag() { return g_interrupted; }

void noteSamplesTaken() { g_exit_at_once.store(false); }
void noteNothingToSave() { g_exit_at_once.store(g_exit_until_samples); }

const std::atomic<bool>* installInterruptHandler(bool exit_until_samples) {
  g_interrupted.store(false);
  g_exit_until_samples = exit_until_samples;
  g_exit_at_once.store(exit_until_samples);
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
