// The primitives' distances at many points at once, for the block evaluator
// (eval/block_evaluator.h): each is the catalogue's `distance` inlined into a
// loop over x, y, z arrays, so every point gets exactly the same operations.
#pragma once
#include "shapes/primitives.h"

namespace sdfc {

using BlockDistance = void (*)(const double* args, const double* x, const double* y, const double* z,
                               double* out, int n);
// Null for polygon, whose points are in the node, not in args. A primitive
// added to the catalogue needs one line in primitives.cpp's blockDistance.
BlockDistance blockDistance(PrimitiveKind kind);

}  // namespace sdfc
