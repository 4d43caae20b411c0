#include "shapes/polygon.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "shapes/primitives.h"

namespace sdfc {
namespace {

using glm::dvec2;

double cross(dvec2 a, dvec2 b) { return a.x * b.y - a.y * b.x; }

// Whether the closed segments ab and cd share a point (collinear overlaps and
// touching ends included).
bool segmentsMeet(dvec2 a, dvec2 b, dvec2 c, dvec2 d) {
  const double d1 = cross(b - a, c - a), d2 = cross(b - a, d - a);
  const double d3 = cross(d - c, a - c), d4 = cross(d - c, b - c);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return true;
  auto onSegment = [](dvec2 p, dvec2 q, dvec2 r, double side) {
    return side == 0 && std::min(p.x, q.x) <= r.x && r.x <= std::max(p.x, q.x) &&
           std::min(p.y, q.y) <= r.y && r.y <= std::max(p.y, q.y);
  };
  return onSegment(a, b, c, d1) || onSegment(a, b, d, d2) || onSegment(c, d, a, d3) || onSegment(c, d, b, d4);
}

std::string literal(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  std::string s = buf;
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

std::string vec2Literal(dvec2 v) { return "vec2(" + literal(v.x) + ", " + literal(v.y) + ")"; }

}  // namespace

double polygonDistance(const std::vector<dvec2>& v, dvec2 p, double axis) {
  // The nearest edge gives the distance; the crossings of a ray from p
  // towards +x give the side (even-odd).
  double best = 1e300;
  bool inside = false;
  for (size_t i = 0; i < v.size(); ++i) {
    const dvec2 a = v[i], b = v[(i + 1) % v.size()];
    if (a.x == axis && b.x == axis) continue;
    const dvec2 e = b - a, w = p - a;
    const double t = std::clamp(glm::dot(w, e) / glm::dot(e, e), 0.0, 1.0);
    const dvec2 h = w - e * t;
    best = std::min(best, glm::dot(h, h));
    if ((p.y < a.y) != (p.y < b.y) && p.x < a.x + (p.y - a.y) * e.x / e.y) inside = !inside;
  }
  return std::sqrt(best) * (inside ? -1.0 : 1.0);
}

Aabb polygonBounds(const std::vector<dvec2>& v) {
  Aabb b;
  for (const dvec2& p : v) {
    b.lo = glm::min(b.lo, glm::dvec3(p, 0));
    b.hi = glm::max(b.hi, glm::dvec3(p, 0));
  }
  return b;
}

std::string polygonProblem(const std::vector<dvec2>& v) {
  const size_t n = v.size();
  if (n < 3) return "a polygon needs at least 3 points, got " + std::to_string(n);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j)
      if (v[i] == v[j])
        return "points " + std::to_string(i + 1) + " and " + std::to_string(j + 1) + " are the same point";
  for (size_t i = 0; i < n; ++i) {
    const dvec2 a = v[i], b = v[(i + 1) % n];
    for (size_t j = i + 1; j < n; ++j) {
      const dvec2 c = v[j], d = v[(j + 1) % n];
      const bool next = j == i + 1, wraps = i == 0 && j == n - 1;
      if (next || wraps) {
        // Neighbours share one corner; they must not fold back along each other.
        const dvec2 shared = next ? b : a, far_mine = next ? a : b, far_theirs = next ? d : c;
        const dvec2 e1 = far_mine - shared, e2 = far_theirs - shared;
        if (cross(e1, e2) == 0 && glm::dot(e1, e2) > 0) {
          return "edges " + std::to_string(i + 1) + " and " + std::to_string(j + 1) + " overlap";
        }
        continue;
      }
      if (segmentsMeet(a, b, c, d))
        return "edges " + std::to_string(i + 1) + " and " + std::to_string(j + 1) +
               " cross; the polygon must not intersect itself";
    }
  }
  // Last: a simple polygon has area, unless it is too thin for float64.
  double area = 0;
  for (size_t i = 0; i < n; ++i) area += cross(v[i], v[(i + 1) % n]);
  if (std::fabs(area) <= 1e-12 * std::max(1.0, glm::dot(v[0], v[0]))) return "the polygon has no area";
  return "";
}

std::string polygonGlsl(const std::string& name, const std::vector<dvec2>& v, double axis) {
  std::ostringstream g;
  g << "// polygon of " << v.size() << " points: nearest edge, even-odd crossings (shapes/polygon.cpp)"
    << (axis > -HUGE_VAL ? "; revolved, so its edges on x = " + literal(axis + 0.0) + " are not surface" : "") << ".\n";
  g << "float " << name << "(vec3 p) {\n  vec2 q = p.xy;\n  float d = 1e30;\n  float s = 1.0;\n  vec2 w, h;\n";
  for (size_t i = 0; i < v.size(); ++i) {
    const dvec2 a = v[i], b = v[(i + 1) % v.size()];
    if (a.x == axis && b.x == axis) continue;
    const dvec2 e = b - a;
    g << "  w = q - " << vec2Literal(a) << ";\n";
    g << "  h = w - " << vec2Literal(e) << " * clamp(dot(w, " << vec2Literal(e) << ") * "
      << literal(1 / glm::dot(e, e)) << ", 0.0, 1.0);\n";
    g << "  d = min(d, dot(h, h));\n";
    // A level edge never crosses the horizontal through q.
    if (a.y != b.y)
      g << "  if ((q.y < " << literal(a.y) << ") != (q.y < " << literal(b.y) << ") && q.x < "
        << literal(a.x) << " + (q.y - " << literal(a.y) << ") * " << literal(e.x / e.y) << ") s = -s;\n";
  }
  g << "  return s * sqrt(d);\n}\n";
  return g.str();
}

}  // namespace sdfc
