#include "stage_timings.h"

#include <time.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>

namespace sdfc {
namespace {

using Clock = std::chrono::steady_clock;
Clock::time_point g_main_entered = Clock::now();  // until markMainEntered
double g_start_to_main = 0;

// /proc/self/stat's 22nd field: the start time in clock ticks since boot,
// against CLOCK_BOOTTIME now.
double secondsSinceProcessStart() {
  std::ifstream in("/proc/self/stat");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t paren = text.rfind(')');  // the command name may hold spaces
  if (paren == std::string::npos) return 0;
  std::istringstream fields(text.substr(paren + 2));
  std::string field;
  unsigned long long start_ticks = 0;
  for (int i = 3; i <= 22 && fields >> field; ++i)
    if (i == 22) start_ticks = std::stoull(field);
  const long ticks_per_second = sysconf(_SC_CLK_TCK);
  timespec now{};
  if (start_ticks == 0 || ticks_per_second <= 0 || clock_gettime(CLOCK_BOOTTIME, &now) != 0) return 0;
  const double since = double(now.tv_sec) + now.tv_nsec * 1e-9 - double(start_ticks) / ticks_per_second;
  return since > 0 ? since : 0;
}

}  // namespace

void markMainEntered() {
  g_main_entered = Clock::now();
  g_start_to_main = secondsSinceProcessStart();
}

double processStartToMainSeconds() { return g_start_to_main; }

double secondsSinceMain() {
  return std::chrono::duration<double>(Clock::now() - g_main_entered).count();
}

void StageTimings::add(std::string name, double seconds, std::string note, bool beside) {
  stages.push_back({std::move(name), seconds, std::move(note), beside});
}

void StageTimings::print() const {
  const double total = processStartToMainSeconds() + secondsSinceMain();
  std::fprintf(stderr, "sdfc: timings (ms):\n");
  double listed = 0;
  for (const Stage& s : stages) {
    if (!s.beside) listed += s.seconds;
    std::fprintf(stderr, "  %-34s %9.1f  %5.1f%%%s%s\n", s.name.c_str(), s.seconds * 1000,
                 total > 0 ? 100 * s.seconds / total : 0.0, s.note.empty() ? "" : "  ",
                 s.note.c_str());
  }
  std::fprintf(stderr, "  %-34s %9.1f  %5.1f%%\n", "other", (total - listed) * 1000,
               total > 0 ? 100 * (total - listed) / total : 0.0);
  std::fprintf(stderr, "  %-34s %9.1f\n", "total (process start to exit)", total * 1000);
}

}  // namespace sdfc
