#include "option_limits.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace sdfc::api {
namespace {

constexpr double kFloatMax = std::numeric_limits<float>::max();

// Whole values in full (1048576, not 1.04858e+06).
std::string number(double v) {
  char buf[32];
  if (v == std::floor(v) && std::fabs(v) < 1e15) std::snprintf(buf, sizeof buf, "%.0f", v);
  else std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

}  // namespace

const std::vector<OptionLimit>& optionLimits() {
  // The ranges the command line's flags had. Time and a cell's size are
  // float32 in the shader, so finite there; exposure's 2^64 either way is far
  // past any use and still finite in float32.
  static const std::vector<OptionLimit> table = {
      {Option::Spp, "spp", "--spp", true, true, 1, 1 << 20, false, ""},
      {Option::Bounces, "bounces", "--bounces", true, true, 0, 64, false, ""},
      {Option::LightSamples, "light_samples", "--light-samples", true, true, 0, 16, false, ""},
      {Option::Size, "size", "--size", true, true, 1, 16384, false, "each side"},
      {Option::Time, "time", "--time", true, false, -kFloatMax, kFloatMax, false, ""},
      {Option::Seed, "seed", "--seed", true, true, 0, 4294967295.0, false, ""},
      {Option::Exposure, "exposure", "--exposure", false, false, -64, 64, false, "stops"},
      {Option::Resolution, "resolution", "--resolution", true, true, 4, 1024, false, ""},
      {Option::VoxelSize, "voxel_size", "--voxel-size", true, false, 0, kFloatMax, true, ""},
      {Option::Threads, "threads", "", true, true, 0, 4096, false, "0: every core"},
  };
  return table;
}

const OptionLimit& optionLimit(Option option) {
  for (const OptionLimit& limit : optionLimits())
    if (limit.option == option) return limit;
  throw std::logic_error("an option without a limit");
}

std::string optionRange(const OptionLimit& l) {
  if (!l.whole && l.lo == -kFloatMax && l.hi == kFloatMax) return "a finite number within float32's range (±3.40282e+38)";
  std::string out = l.whole ? "a whole number " : "a number ";
  if (l.open_low) out += "above " + number(l.lo) + " and at most " + number(l.hi);
  else out += "from " + number(l.lo) + " to " + number(l.hi);
  return out;
}

std::string optionProblem(Option option, double value, const std::string& spelled) {
  const OptionLimit& l = optionLimit(option);
  const bool inside = std::isfinite(value) && (l.open_low ? value > l.lo : value >= l.lo) && value <= l.hi &&
                      (!l.whole || value == std::floor(value));
  if (inside) return "";
  return spelled + " must be " + optionRange(l) + (*l.note ? std::string(" (") + l.note + ")" : "") + ", got " +
         number(value);
}

}  // namespace sdfc::api
