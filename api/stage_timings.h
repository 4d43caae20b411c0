// --timings: the fixed stages of one run (process start, device, front end,
// glslang, validation, pipeline, the first draw's kernel compile, passes,
// readback, encoding), collected in order and printed as one table on stderr.
#pragma once
#include <chrono>
#include <string>
#include <vector>

namespace sdfc {

// Called first thing in main(): remembers when main was entered and how long
// after the process's start (the kernel's start time, in clock ticks).
void markMainEntered();
// Seconds from the process's start to main (dynamic loading, static
// initialisers); 0 when /proc cannot tell. Resolution: one clock tick (10 ms).
double processStartToMainSeconds();
// Seconds since main was entered.
double secondsSinceMain();

struct StageTimings {
  struct Stage {
    std::string name;
    double seconds = 0;
    std::string note;
    bool beside = false;  // ran beside other stages: not part of the sum
  };
  std::vector<Stage> stages;

  void add(std::string name, double seconds, std::string note = "", bool beside = false);
  // "sdfc: timings:" and a line per stage (milliseconds, share of `total`), then
  // the total: main to now, plus process start to main.
  void print() const;
};

}  // namespace sdfc
