// The noisy halves and features `sdfc render` hands nlr (api/scene_render.cpp),
// rendered once, for the bench tools that run the filter on them many times
// (sdfc_denoise_speed, sdfc_nlr_tune).
#pragma once
#include <string>
#include <utility>

#include "renderer.h"

namespace sdfc::bench {

struct NlrInput {
  RenderOutput out;     // features resolved from the jittered AOVs
  SampleHalves halves;  // the two halves' means, for the variance-guided filters
};

// False, after saying why on stderr with `tool`'s name, when the scene does not
// compile.
bool renderNlrInput(const std::string& scene_path, std::pair<int, int> size, int spp, int seed, const char* tool,
                    NlrInput& input);

// This process's CPU time so far (user and system), in milliseconds.
double processCpuMs();

}  // namespace sdfc::bench
