// The range of every option more than one front end takes: the command line
// (its flags' checks), the Python package (its keyword arguments) and the
// viewer (its script's `spp`) all ask this table, so a value one refuses no
// other accepts (Python took light_samples=-1 as 4294967295, bounces=1000,
// time=nan and voxel_size=nan, all refused by the command line).
// docs/python.md quotes these ranges; tests/option_limits_test.py walks the
// table through every front end.
#pragma once
#include <optional>
#include <string>
#include <vector>

namespace sdfc::api {

enum class Option { Spp, Bounces, LightSamples, Size, Time, Seed, Exposure, Resolution, VoxelSize, Threads };

struct OptionLimit {
  Option option;
  const char* name;  // Python's keyword (light_samples)
  const char* flag;  // the command line's flag (--light-samples); "" when it has none
  bool python;       // a keyword of the Python package
  bool whole;        // a whole number; else any finite number
  double lo, hi;     // the range, both ends included unless open_low
  bool open_low;     // lo itself excluded (voxel_size > 0)
  const char* note;  // what a value outside means, or "" (0 threads: every core)
};

// Every option, in the order the documentation lists them.
const std::vector<OptionLimit>& optionLimits();
const OptionLimit& optionLimit(Option option);

// "" when `value` is within `option`'s range (whole where it must be, finite);
// else the message, naming the option as `spelled` ("--bounces", "bounces"):
// "bounces must be a whole number from 0 to 64, got 1000".
std::string optionProblem(Option option, double value, const std::string& spelled);

// The range as words: "a whole number from 0 to 64", "a number above 0 and at
// most 3.40282e+38".
std::string optionRange(const OptionLimit& limit);

}  // namespace sdfc::api
