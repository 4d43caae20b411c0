// The primitive catalogue: one entry per primitive holds everything about it
// (parameters, exact float64 distance, GLSL, bounds), so adding a primitive
// is one edit here and nowhere else.
#pragma once
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
};

enum class ParamType { Number, Vector };
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
  Octahedron, Pyramid, RoundCone, Ellipsoid
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

// Largest Menger level accepted: each level adds one loop pass, and level 8
// holes are 3^-8 ~ 1.5e-4 of the sponge, near float32 marching precision.
constexpr int kMaxMengerLevel = 8;

}  // namespace sdfc
