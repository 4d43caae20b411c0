// Debug views for display (PNG and `sdfc view`): the kernel writes raw values
// (depth in scene units, march steps, loop iterations), which EXR and PFM keep;
// a display needs them mapped into a range it can show (issue 29: a raw depth
// of 20 was all white, 400 iterations all red). docs/debug_views.md says what
// each view's colours mean.
#pragma once
#include <cstdint>

#include "float_image.h"

namespace sdfc {

// The budgets the counting views are drawn against.
struct DebugViewBudget {
  uint32_t max_steps = 1;   // the scene's march step budget (steps view)
  uint32_t iterations = 1;  // loop iterations of a one-sample pass, worst case (iterations view)
};

// A render's budgets: the scene's step budget (its emitted march limits) and the
// settings' loop-iteration bound of one sample plus the pass's AOV ray.
struct RenderSettings;
DebugViewBudget debugViewBudget(uint32_t max_steps, const RenderSettings& settings);

// True for views whose raw values need mapping for display: depth, steps, iterations.
bool debugViewNeedsMapping(uint32_t view);

// The displayed image of a debug view: linear RGB, to be written with the linear
// (clamp) tone curve so the bytes are the colour map's own sRGB values.
//   depth:      viridis over log(depth) between the 1st and 90th percentiles of the
//               image's hits, near bright (yellow), far dark (purple); misses grey.
//   steps:      viridis over log(1 + steps) / log(1 + max_steps).
//   iterations: viridis over log(1 + iterations) / log(1 + budget).
// Other views are returned as they are.
FloatImage debugViewForDisplay(uint32_t view, const FloatImage& raw, const DebugViewBudget& budget);

// The viridis colour map at t in [0, 1] (clamped), sRGB-encoded.
void viridis(float t, float rgb[3]);

}  // namespace sdfc
