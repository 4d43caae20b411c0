// twist and bend (passes/analyze.cpp): the deformed field is used out to a
// little beyond the radius of the cylinder holding the shape, so that the
// cylinder's distance, used outside, is never 0 (a march stopping on the
// cylinder would take it for the surface: rays ended on it, short of the
// shape); the Lipschitz factor is taken at that reach.
#pragma once
#include "ir/scene.h"

namespace sdfc {

inline double deformReach(const ir::Node& n) { return n.deform_radius * (1 + 1.0 / 16); }

}  // namespace sdfc
