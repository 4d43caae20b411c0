// polygon(points): the one profile whose size is not fixed. Its points are
// constants kept in the node; this file holds what the catalogue entry
// cannot: the simplicity check and the GLSL written per polygon.
#pragma once
#include <cmath>
#include <glm/glm.hpp>
#include <string>
#include <vector>

namespace sdfc {

// Why `points` is not a simple polygon ("" when it is): fewer than 3 points,
// a repeated point, no area, or two edges that meet other than at their
// shared corner (the first such pair is named, counting edges from 1).
std::string polygonProblem(const std::vector<glm::dvec2>& points);

// A GLSL function `float <name>(vec3 p)` for this polygon, unrolled per edge
// (a loop would count against lavapipe's loop cap at every march step);
// edges on x = `axis` left out, as polygonDistance does.
std::string polygonGlsl(const std::string& name, const std::vector<glm::dvec2>& points, double axis = -HUGE_VAL);

}  // namespace sdfc
