#include "driver_compile_level.h"

#include <cstdlib>

namespace sdfc {

bool chooseQuickDriverCompile(uint64_t samples) {
  if (samples == 0 || samples > kQuickCompileMaxSamples || std::getenv("GALLIVM_PERF")) return false;
  return setenv("GALLIVM_PERF", "nopt", 1) == 0;
}

}  // namespace sdfc
