// The nlm/nlr filter as it was at ab4eac1: bench/denoise_speed's baseline.
#pragma once
#include "denoise_nlm.h"

namespace sdfc::legacy {

FloatImage nlmDenoise(const SampleHalves& halves, const FloatImage& normal_depth,
                      const FloatImage& albedo_steps, const NlmParams& params = {},
                      SampleHalves* filtered = nullptr);

}  // namespace sdfc::legacy
