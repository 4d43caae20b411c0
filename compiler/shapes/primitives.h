// The primitive catalogue: one entry per primitive holds everything about it
// (parameters, exact float64 distance, GLSL, bounds), so adding a primitive
// is one edit here and nowhere else.
#pragma once
#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <string>
#include <vector>

namespace sdfc {

struct Aabb {
  glm::dvec3 lo{1e300}, hi{-1e300};  // empty by default
  static Aabb infinite() { return {glm::dvec3(-1e300), glm::dvec3(1e300)}; }
  bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
  bool finite() const;
  glm::dvec3 center() const { return (lo + hi) * 0.5; }
  glm::dvec3 halfSize() const { return (hi - lo) * 0.5; }
  Aabb unite(const Aabb& o) const { return {glm::min(lo, o.lo), glm::max(hi, o.hi)}; }
  Aabb intersect(const Aabb& o) const { return {glm::max(lo, o.lo), glm::min(hi, o.hi)}; }
  Aabb grow(double r) const { return {lo - r, hi + r}; }
  // From p to the box (0 inside): a lower bound on the distance to anything in it.
  double distance(const glm::dvec3& p) const { return glm::length(glm::max(glm::max(lo - p, p - hi), glm::dvec3(0))); }
  // Negative inside (the distance to the nearest face): a lower bound on any
  // shape within the box, at points inside it too.
  double signedDistance(const glm::dvec3& p) const {
    const glm::dvec3 e = glm::max(lo - p, p - hi);
    return glm::length(glm::max(e, glm::dvec3(0))) + std::min(std::max(e.x, std::max(e.y, e.z)), 0.0);
  }
  // Between two boxes (0 where they touch or overlap), squared and not.
  double gapSquared(const Aabb& o) const {
    const glm::dvec3 gap = glm::max(glm::max(lo - o.hi, o.lo - hi), glm::dvec3(0));
    return glm::dot(gap, gap);
  }
  double distance(const Aabb& o) const { return std::sqrt(gapSquared(o)); }
};

// Vector2: a 2-vector [x, y] (profiles); Points: a constant list of them
// (polygon), read from the syntax and kept in the node, not in its args.
enum class ParamType { Number, Vector, Vector2, Points };
enum class ParamRule { Any, Positive, NonNegative, NonZeroVector, PositiveVector };

struct ParamSpec {
  const char* name;
  ParamType type;
  ParamRule rule;
  bool has_default;
  glm::dvec3 default_value;  // Number uses .x
};

enum class PrimitiveKind {
  Sphere, Box, Torus, Cylinder, Cone, Plane, Capsule, TriPrism, HexPrism, Menger,
  Octahedron, Pyramid, RoundCone, Ellipsoid,
  // 2D profiles in the xy plane (z = 0): only the block of extrude/revolve.
  Circle, Rect, Hexagon, Polygon
};

struct PrimitiveInfo {
  PrimitiveKind kind;
  const char* name;             // in .sdf
  std::vector<ParamSpec> params;
  // Arguments are the parameters flattened (a vector takes 3 slots).
  double (*distance)(const double* args, const glm::dvec3& p);
  Aabb (*bounds)(const double* args);
  const char* glsl_function;    // name of its GLSL function
  const char* glsl_source;      // the GLSL function definition
  bool exact;                   // Euclidean distance (true) or only a bound
  const char* summary;
  // A 2D profile: its distance reads p.xy only, it is evaluated at z = 0
  // (extrude and revolve put it there) and its bounds are flat (z = 0).
  bool profile = false;
};

const std::vector<PrimitiveInfo>& primitiveCatalogue();
const PrimitiveInfo* findPrimitive(const std::string& name);
const PrimitiveInfo& primitiveInfo(PrimitiveKind kind);
int flattenedParamCount(const PrimitiveInfo& info);
// The most flattened parameters any primitive takes (box and plane take 4).
constexpr size_t kMaxPrimitiveArgs = 8;
// GLSL of the 2D box helper some primitives share (sdBox2).
const char* box2Glsl();
// GLSL of the point-triangle distance the octahedron and pyramid share.
const char* triangleGlsl();

// polygon(points): exact signed distance to the closed polygon through
// `points` (inside by the even-odd rule; the checker accepts only simple
// polygons, where that is the inside), at p.xy; and its flat bounds. Edges
// lying on the line x = `axis` are left out: a lathe's profile, revolved
// about that line, has no surface there (p.x >= axis, where such an edge
// never changes the side either).
double polygonDistance(const std::vector<glm::dvec2>& points, glm::dvec2 p, double axis = -HUGE_VAL);
Aabb polygonBounds(const std::vector<glm::dvec2>& points);
// Most points a polygon takes: its GLSL is unrolled, one edge a few lines.
constexpr size_t kMaxPolygonPoints = 64;

// Largest Menger level accepted: each level adds one loop pass, and level 8
// holes are 3^-8 ~ 1.5e-4 of the sponge, near float32 marching precision.
constexpr int kMaxMengerLevel = 8;

}  // namespace sdfc
