// Names other SDF tools use (fogleman/sdf, libfive, Curv, Inigo Quilez's
// GLSL catalogue) for things sdfc spells differently. An edit distance cannot
// find `union(smooth:)` from `smooth_union`, so the checker asks this table
// first when a call names an unknown function.
#pragma once
#include <string>

namespace sdfc {

// The sdfc spelling to suggest for `name`, as text for "did you mean ...?",
// or "" when `name` is not a known spelling of another tool.
std::string otherToolSpelling(const std::string& name);

}  // namespace sdfc
