// twist and bend (passes/analyze.cpp): the deformed field is used out to a
// little beyond the radius of the cylinder holding the shape, so that the
// cylinder's distance, used outside, is never 0 (a march stopping on the
// cylinder would take it for the surface: rays ended on it, short of the
// shape); the Lipschitz factor is taken at that reach.
//
// A boxed bend (deform_boxed) is used only within its bounds' x-z rectangle
// grown by the same margin, radius / 16, where the map stretches less than
// over the whole disc; outside, the distance to its bounds is used too.
#pragma once
#include <algorithm>
#include <cmath>

#include "ir/scene.h"

namespace sdfc {

inline double deformReach(const ir::Node& n) { return n.deform_radius * (1 + 1.0 / 16); }
inline double deformMargin(const ir::Node& n) { return n.deform_radius / 16; }

// Whether the deformed field, divided by deform_lipschitz, holds at p.
inline bool deformedAt(const ir::Node& n, const glm::dvec3& p) {
  if (p.x * p.x + p.z * p.z > deformReach(n) * deformReach(n)) return false;
  if (!n.deform_boxed) return true;
  const double m = deformMargin(n);
  return p.x >= n.bounds.lo.x - m && p.x <= n.bounds.hi.x + m && p.z >= n.bounds.lo.z - m &&
         p.z <= n.bounds.hi.z + m;
}

// Elsewhere: the distance to the cylinder (its height the child's), and to a
// boxed bend's bounds, both lower bounds (the shape lies in each).
inline double deformOutside(const ir::Node& n, const glm::dvec3& p) {
  const Aabb& b = n.children[0]->bounds;
  const double r = std::sqrt(p.x * p.x + p.z * p.z);
  const glm::dvec2 w(r - n.deform_radius, std::fabs(p.y - (b.lo.y + b.hi.y) / 2) - (b.hi.y - b.lo.y) / 2);
  const double cylinder = std::min(std::max(w.x, w.y), 0.0) + glm::length(glm::max(w, glm::dvec2(0)));
  return n.deform_boxed ? std::max(cylinder, n.bounds.distance(p)) : cylinder;
}

}  // namespace sdfc
