// Exact distances follow Inigo Quilez's catalogue ("distance functions",
// iquilezles.org/articles/distfunctions) unless noted; every one is checked
// against an independent closed form and a brute-force surface sampling in
// tests/primitives_test.cpp. The seed paper's torus, cylinder, cone and box
// formulas are bounds or wrong; these are not.
#include "shapes/primitives.h"

#include <algorithm>
#include <cmath>

#include "shapes/primitive_blocks.h"

namespace sdfc {
namespace {

using glm::dvec2;
using glm::dvec3;

double len2(dvec2 v) { return std::sqrt(v.x * v.x + v.y * v.y); }

// Exact distance to the 2D box |x| <= h, the core of every extrusion below.
double box2(dvec2 q) {
  return len2(glm::max(q, dvec2(0))) + std::min(std::max(q.x, q.y), 0.0);
}

double sphere(const double* a, const dvec3& p) { return glm::length(p) - a[0]; }
Aabb sphereBounds(const double* a) { return {dvec3(-a[0]), dvec3(a[0])}; }

// box(size, rounding): full side lengths; rounding rounds the edges inward.
double box(const double* a, const dvec3& p) {
  const dvec3 h = dvec3(a[0], a[1], a[2]) * 0.5 - a[3];
  const dvec3 q = glm::abs(p) - h;
  return glm::length(glm::max(q, dvec3(0))) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0) -
         a[3];
}
Aabb boxBounds(const double* a) {
  const dvec3 h = dvec3(a[0], a[1], a[2]) * 0.5;
  return {-h, h};
}

// torus(major, minor): ring in the xz plane (the paper's uses xy and is not
// a distance at all: it subtracts r2^2 under the root).
double torus(const double* a, const dvec3& p) {
  return len2(dvec2(len2(dvec2(p.x, p.z)) - a[0], p.y)) - a[1];
}
Aabb torusBounds(const double* a) {
  const double r = a[0] + a[1];
  return {dvec3(-r, -a[1], -r), dvec3(r, a[1], r)};
}

// cylinder(radius, height): axis y, centred; the paper's uses p.xy for the
// radius (wrong axis) and max() (a bound outside the rims).
double cylinder(const double* a, const dvec3& p) {
  return box2(dvec2(len2(dvec2(p.x, p.z)) - a[0], std::fabs(p.y) - a[1] * 0.5));
}
Aabb cylinderBounds(const double* a) {
  return {dvec3(-a[0], -a[1] * 0.5, -a[0]), dvec3(a[0], a[1] * 0.5, a[0])};
}

// cone(radius, height): base disc radius r at y = 0, apex at y = h. Exact
// distance to the solid of revolution of the triangle (0,0)-(r,0)-(0,h):
// the nearer of the base segment and the slant segment, signed by inside-ness.
double cone(const double* a, const dvec3& p) {
  const double r = a[0], h = a[1];
  const dvec2 q(len2(dvec2(p.x, p.z)), p.y);
  // Base segment from (0,0) to (r,0).
  const dvec2 to_base = q - dvec2(std::clamp(q.x, 0.0, r), 0.0);
  // Slant segment from (r,0) to (0,h).
  const dvec2 e(-r, h);
  const double t = std::clamp(glm::dot(q - dvec2(r, 0), e) / glm::dot(e, e), 0.0, 1.0);
  const dvec2 to_slant = q - (dvec2(r, 0) + e * t);
  const double d = std::sqrt(std::min(glm::dot(to_base, to_base), glm::dot(to_slant, to_slant)));
  // Inside: above the base and below the slant line (q.x/r + q.y/h < 1).
  const bool inside = q.y > 0 && q.x * h + q.y * r < r * h;
  return inside ? -d : d;
}
Aabb coneBounds(const double* a) { return {dvec3(-a[0], 0, -a[0]), dvec3(a[0], a[1], a[0])}; }

// plane(normal, offset): the half-space dot(p, n) <= offset, n normalised.
double plane(const double* a, const dvec3& p) {
  const dvec3 n = glm::normalize(dvec3(a[0], a[1], a[2]));
  return glm::dot(p, n) - a[3];
}
Aabb planeBounds(const double*) { return Aabb::infinite(); }

// capsule(radius, height): a segment along y of length `height`, centred.
double capsule(const double* a, const dvec3& p) {
  const double h = a[1] * 0.5;
  return glm::length(dvec3(p.x, p.y - std::clamp(p.y, -h, h), p.z)) - a[0];
}
Aabb capsuleBounds(const double* a) {
  return {dvec3(-a[0], -a[1] * 0.5 - a[0], -a[0]), dvec3(a[0], a[1] * 0.5 + a[0], a[0])};
}

// Exact distance to an equilateral triangle of side s in the xy plane,
// centred on its centroid, apex up: the distance to the nearest edge,
// negative inside. Edges are tested directly (no symmetry folding) so that
// this form is independent of the GLSL one.
double triangle2(dvec2 p, double s) {
  const double h = s * std::sqrt(3.0) / 2;
  const dvec2 v[3] = {dvec2(-s / 2, -h / 3), dvec2(s / 2, -h / 3), dvec2(0, 2 * h / 3)};
  double best = 1e300;
  bool inside = true;
  for (int i = 0; i < 3; ++i) {
    const dvec2 a = v[i], b = v[(i + 1) % 3];
    const dvec2 e = b - a, w = p - a;
    const double t = std::clamp(glm::dot(w, e) / glm::dot(e, e), 0.0, 1.0);
    best = std::min(best, glm::length(w - e * t));
    if (e.x * w.y - e.y * w.x < 0) inside = false;  // counter-clockwise vertices
  }
  return inside ? -best : best;
}

// prism(size, depth): equilateral triangle of side `size` (xy, apex +y),
// extruded along z over `depth`. Exact, as an extrusion of an exact 2D
// distance (Quilez's opExtrusion); his sdTriPrism is only a bound.
double triPrism(const double* a, const dvec3& p) {
  return box2(dvec2(triangle2(dvec2(p.x, p.y), a[0]), std::fabs(p.z) - a[1] * 0.5));
}
Aabb triPrismBounds(const double* a) {
  const double h = a[0] * std::sqrt(3.0) / 2;
  return {dvec3(-a[0] / 2, -h / 3, -a[1] / 2), dvec3(a[0] / 2, 2 * h / 3, a[1] / 2)};
}

// hexprism(radius, depth): regular hexagon with inradius `radius` in xy
// (flat top and bottom), extruded along z. Exact as an extrusion.
double hexagon2(dvec2 p, double r) {
  // Fold into one sextant: the distance to the edge y = r over |x| <= r/sqrt3.
  p = glm::abs(p);
  const dvec2 k(-std::sqrt(3.0) / 2, 0.5);  // normal of the slanted mirror line
  p -= 2.0 * std::min(glm::dot(k, p), 0.0) * k;
  const double half = r / std::sqrt(3.0);
  const dvec2 to_edge = p - dvec2(std::clamp(p.x, -half, half), r);
  return glm::length(to_edge) * (p.y > r ? 1.0 : -1.0);
}
double hexPrism(const double* a, const dvec3& p) {
  return box2(dvec2(hexagon2(dvec2(p.x, p.y), a[0]), std::fabs(p.z) - a[1] * 0.5));
}
Aabb hexPrismBounds(const double* a) {
  const double c = a[0] * 2 / std::sqrt(3.0);
  return {dvec3(-c, -a[0], -a[1] / 2), dvec3(c, a[0], a[1] / 2)};
}

// ---- 2D profiles (xy plane; Quilez, "2D distance functions",
// iquilezles.org/articles/distfunctions2d). Each reads p.xy only; bounds are
// flat at z = 0, where extrude and revolve evaluate them.

// circle(radius).
double circle(const double* a, const dvec3& p) { return len2(dvec2(p.x, p.y)) - a[0]; }
Aabb circleBounds(const double* a) { return {dvec3(-a[0], -a[0], 0), dvec3(a[0], a[0], 0)}; }

// rect(size, rounding): full side lengths [x, y], corners rounded by
// `rounding` (the inner box grown by it: exact).
double rect(const double* a, const dvec3& p) {
  const dvec2 h = dvec2(a[0], a[1]) * 0.5 - a[2];
  return box2(glm::abs(dvec2(p.x, p.y)) - h) - a[2];
}
Aabb rectBounds(const double* a) {
  return {dvec3(-a[0] / 2, -a[1] / 2, 0), dvec3(a[0] / 2, a[1] / 2, 0)};
}

// hexagon(radius): inradius `radius`, flat top and bottom (hexprism's
// cross-section).
double hexagon(const double* a, const dvec3& p) { return hexagon2(dvec2(p.x, p.y), a[0]); }
Aabb hexagonBounds(const double* a) {
  const double c = a[0] * 2 / std::sqrt(3.0);
  return {dvec3(-c, -a[0], 0), dvec3(c, a[0], 0)};
}

// polygon(points) keeps its points in the node (shapes/polygon.cpp); the
// catalogue entry is for its name, parameters and docs.
double polygonUnused(const double*, const dvec3&) { return 1e300; }
Aabb polygonUnusedBounds(const double*) { return Aabb::infinite(); }

// menger(level, size): a cube of side `size` minus, per level k, the
// infinitely repeated cross of square bars (period size/3^(k-1), bar width a
// third of it). Each repeated cross is an exact distance; their max is a
// bound (exact inside), Lipschitz 1.
double menger(const double* a, const dvec3& p) {
  const int level = static_cast<int>(a[0]);
  const double size = a[1];
  const double half = size / 2;
  const dvec3 q = glm::abs(p) - dvec3(half);
  double d = glm::length(glm::max(q, dvec3(0))) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0);
  double cell = size;  // period of this level's crosses
  for (int k = 0; k < level; ++k) {
    // Coordinates relative to the nearest cell centre; the cube's corner is a cell corner.
    dvec3 r = p + dvec3(half);
    r = r - cell * glm::floor(r / cell) - dvec3(cell / 2);
    r = glm::abs(r);
    const double w = cell / 6;  // half width of the bars
    // Distance to the union of three infinite bars (each a 2D square in the
    // other two axes): inside the cross when two coordinates are under w.
    const double bx = box2(dvec2(r.y - w, r.z - w));
    const double by = box2(dvec2(r.z - w, r.x - w));
    const double bz = box2(dvec2(r.x - w, r.y - w));
    d = std::max(d, -std::min(bx, std::min(by, bz)));
    cell /= 3;
  }
  return d;
}
Aabb mengerBounds(const double* a) { return {dvec3(-a[1] / 2), dvec3(a[1] / 2)}; }

// Distance from p to the triangle abc (no sign): the nearest of the face's
// interior, its edges and its vertices (Ericson, Real-Time Collision
// Detection, 5.1.5: the region of p by its barycentric coordinates).
double triangleDistance(const dvec3& p, const dvec3& a, const dvec3& b, const dvec3& c) {
  const dvec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return glm::length(ap);
  const dvec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return glm::length(bp);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return glm::length(ap - ab * (d1 / (d1 - d3)));
  const dvec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return glm::length(cp);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return glm::length(ap - ac * (d2 / (d2 - d6)));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
    return glm::length(bp - (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))));
  const double denom = 1 / (va + vb + vc);
  return glm::length(ap - ab * (vb * denom) - ac * (vc * denom));
}

// octahedron(radius): |x| + |y| + |z| <= radius. The eight faces are mirror
// images, so the nearest surface point of |p| lies on the face in the
// positive octant; inside, the nearest face is that one's plane.
double octahedron(const double* a, const dvec3& p) {
  const double s = a[0];
  const dvec3 q = glm::abs(p);
  const double m = q.x + q.y + q.z - s;
  if (m <= 0) return m / std::sqrt(3.0);
  return triangleDistance(q, dvec3(s, 0, 0), dvec3(0, s, 0), dvec3(0, 0, s));
}
Aabb octahedronBounds(const double* a) { return {dvec3(-a[0]), dvec3(a[0])}; }

// pyramid(size, height): a square base of side `size` on y = 0, centred, and
// its apex at (0, height, 0). The planes x = 0, z = 0 and x = z are mirror
// planes, so for |p| folded to x >= z >= 0 the nearest surface point lies on
// the +x face or on the base; inside, the nearest of the five face planes.
double pyramid(const double* a, const dvec3& p) {
  const double h2 = a[0] / 2, h = a[1];
  dvec3 q(std::fabs(p.x), p.y, std::fabs(p.z));
  if (q.z > q.x) std::swap(q.x, q.z);
  // Outward unit normal of the +x face: the plane through (h2, 0, *) and the apex.
  const dvec2 n = glm::normalize(dvec2(h, h2));
  const double side = n.x * (q.x - h2) + n.y * q.y;  // signed distance to the face's plane
  if (q.y >= 0 && side <= 0) return std::max(-q.y, side);
  const double to_face = triangleDistance(q, dvec3(h2, 0, h2), dvec3(h2, 0, -h2), dvec3(0, h, 0));
  const dvec3 on_base(std::min(q.x, h2), 0, std::min(q.z, h2));
  return std::min(to_face, glm::length(q - on_base));
}
Aabb pyramidBounds(const double* a) {
  return {dvec3(-a[0] / 2, 0, -a[0] / 2), dvec3(a[0] / 2, a[1], a[0] / 2)};
}

// round_cone(bottom, top, height): the convex hull of a sphere of radius
// `bottom` at the origin and one of radius `top` at (0, height, 0) (needs
// height > |bottom - top|, so neither holds the other). In the meridian
// plane it is the hull of two discs: the line that touches both has unit
// normal (a, b) with b = (bottom - top) / height; a point projects onto the
// bottom disc, the tangent line or the top disc by its coordinate along the
// line's direction (-b, a).
double roundCone(const double* a, const dvec3& p) {
  const double r1 = a[0], r2 = a[1], h = a[2];
  const dvec2 q(len2(dvec2(p.x, p.z)), p.y);
  const double b = (r1 - r2) / h, c = std::sqrt(1 - b * b);
  const double along = glm::dot(q, dvec2(-b, c));
  if (along < 0) return glm::length(q) - r1;
  if (along > c * h) return glm::length(q - dvec2(0, h)) - r2;
  return glm::dot(q, dvec2(c, b)) - r1;
}
Aabb roundConeBounds(const double* a) {
  const double r = std::max(a[0], a[1]);
  return {dvec3(-r, -a[0], -r), dvec3(r, a[2] + a[1], r)};
}

// ellipsoid(radii): a bound. g = |p / radii| - 1 has gradient at most
// 1 / min(radii), so g * min(radii) is 1-Lipschitz, zero on the surface and
// negative inside: a lower bound of the distance, exact on a sphere, and
// min/max(radii) of it far from an elongated one (no closed form exists).
double ellipsoid(const double* a, const dvec3& p) {
  const dvec3 r(a[0], a[1], a[2]);
  return (glm::length(p / r) - 1) * std::min(r.x, std::min(r.y, r.z));
}
Aabb ellipsoidBounds(const double* a) {
  const dvec3 r(a[0], a[1], a[2]);
  return {-r, r};
}

const ParamSpec kRadius{"radius", ParamType::Number, ParamRule::Positive, false, {}};
const ParamSpec kHeight{"height", ParamType::Number, ParamRule::Positive, false, {}};

// GLSL twins of the functions above. They are written for float32 and for
// speed (symmetry folding), so they are tested against the float64 ones.
const char* kSphereGlsl = R"(float sdSphere(vec3 p, float r) { return length(p) - r; }
)";
const char* kBoxGlsl = R"(float sdBox(vec3 p, vec3 size, float rounding) {
  vec3 q = abs(p) - (0.5 * size - rounding);
  return length(max(q, 0.0)) + min(max(q.x, max(q.y, q.z)), 0.0) - rounding;
}
)";
const char* kTorusGlsl = R"(float sdTorus(vec3 p, float major, float minor) {
  return length(vec2(length(p.xz) - major, p.y)) - minor;
}
)";
const char* kBox2Glsl = R"(float sdBox2(vec2 q) { return length(max(q, 0.0)) + min(max(q.x, q.y), 0.0); }
)";
const char* kCylinderGlsl = R"(float sdCylinder(vec3 p, float r, float h) {
  return sdBox2(vec2(length(p.xz) - r, abs(p.y) - 0.5 * h));
}
)";
const char* kConeGlsl = R"(float sdCone(vec3 p, float r, float h) {
  vec2 q = vec2(length(p.xz), p.y);
  vec2 to_base = vec2(q.x - min(q.x, r), q.y);
  vec2 e = vec2(-r, h);
  vec2 to_slant = q - vec2(r, 0.0) - e * clamp(dot(q - vec2(r, 0.0), e) / dot(e, e), 0.0, 1.0);
  float d = sqrt(min(dot(to_base, to_base), dot(to_slant, to_slant)));
  return (q.y > 0.0 && q.x * h + q.y * r < r * h) ? -d : d;
}
)";
const char* kPlaneGlsl = R"(float sdPlane(vec3 p, vec3 n, float offset) { return dot(p, n) - offset; }
)";
const char* kCapsuleGlsl = R"(float sdCapsule(vec3 p, float r, float h) {
  p.y -= clamp(p.y, -0.5 * h, 0.5 * h);
  return length(p) - r;
}
)";
// Equilateral triangle by folding (Quilez, sdEquilateralTriangle), shifted so
// the centroid is at the origin, then extruded.
const char* kTriPrismGlsl = R"(float sdTriPrism(vec3 p, float size, float depth) {
  const float k = sqrt(3.0);
  float r = 0.5 * size;
  vec2 q = vec2(abs(p.x) - r, p.y + r / k);
  if (q.x + k * q.y > 0.0) q = vec2(q.x - k * q.y, -k * q.x - q.y) / 2.0;
  q.x -= clamp(q.x, -2.0 * r, 0.0);
  float d2 = -length(q) * sign(q.y);
  return sdBox2(vec2(d2, abs(p.z) - 0.5 * depth));
}
)";
const char* kHexPrismGlsl = R"(float sdHexPrism(vec3 p, float r, float depth) {
  const vec2 k = vec2(-0.8660254037844386, 0.5);
  vec2 q = abs(p.xy);
  q -= 2.0 * min(dot(k, q), 0.0) * k;
  float half_edge = r * 0.5773502691896258;
  float d2 = length(q - vec2(clamp(q.x, -half_edge, half_edge), r)) * sign(q.y - r);
  return sdBox2(vec2(d2, abs(p.z) - 0.5 * depth));
}
)";
const char* kMengerGlsl = R"(float sdMenger(vec3 p, int level, float size) {
  float half_size = 0.5 * size;
  vec3 q = abs(p) - half_size;
  float d = length(max(q, 0.0)) + min(max(q.x, max(q.y, q.z)), 0.0);
  float cell = size;
  for (int k = 0; k < level; ++k) {
    vec3 r = p + half_size;
    r = abs(r - cell * floor(r / cell) - 0.5 * cell);
    float w = cell / 6.0;
    float bars = min(sdBox2(vec2(r.y - w, r.z - w)),
                     min(sdBox2(vec2(r.z - w, r.x - w)), sdBox2(vec2(r.x - w, r.y - w))));
    d = max(d, -bars);
    cell /= 3.0;
  }
  return d;
}
)";

const char* kCircleGlsl = R"(float sdCircle(vec3 p, float r) { return length(p.xy) - r; }
)";
const char* kRectGlsl = R"(float sdRect(vec3 p, vec2 size, float r) {
  return sdBox2(abs(p.xy) - (0.5 * size - r)) - r;
}
)";
const char* kHexagonGlsl = R"(float sdHexagon(vec3 p, float r) {
  const vec2 k = vec2(-0.8660254037844386, 0.5);
  vec2 q = abs(p.xy);
  q -= 2.0 * min(dot(k, q), 0.0) * k;
  float half_edge = r * 0.5773502691896258;
  return length(q - vec2(clamp(q.x, -half_edge, half_edge), r)) * sign(q.y - r);
}
)";

// Closest-point distance to a triangle (as triangleDistance above); the
// octahedron and the pyramid call it for the one face they fold onto.
const char* kTriangleGlsl = R"(float sdTriangleDistance(vec3 p, vec3 a, vec3 b, vec3 c) {
  vec3 ab = b - a, ac = c - a, ap = p - a;
  float d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) return length(ap);
  vec3 bp = p - b;
  float d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) return length(bp);
  float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return length(ap - ab * (d1 / (d1 - d3)));
  vec3 cp = p - c;
  float d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) return length(cp);
  float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return length(ap - ac * (d2 / (d2 - d6)));
  float va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0)
    return length(bp - (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))));
  float denom = 1.0 / (va + vb + vc);
  return length(ap - ab * (vb * denom) - ac * (vc * denom));
}
)";
const char* kOctahedronGlsl = R"(float sdOctahedron(vec3 p, float s) {
  vec3 q = abs(p);
  float m = q.x + q.y + q.z - s;
  if (m <= 0.0) return m * 0.5773502691896258;
  return sdTriangleDistance(q, vec3(s, 0.0, 0.0), vec3(0.0, s, 0.0), vec3(0.0, 0.0, s));
}
)";
const char* kPyramidGlsl = R"(float sdPyramid(vec3 p, float size, float h) {
  float h2 = 0.5 * size;
  vec3 q = vec3(abs(p.x), p.y, abs(p.z));
  if (q.z > q.x) q.xz = q.zx;
  vec2 n = normalize(vec2(h, h2));
  float side = n.x * (q.x - h2) + n.y * q.y;
  if (q.y >= 0.0 && side <= 0.0) return max(-q.y, side);
  float to_face = sdTriangleDistance(q, vec3(h2, 0.0, h2), vec3(h2, 0.0, -h2), vec3(0.0, h, 0.0));
  return min(to_face, length(q - vec3(min(q.x, h2), 0.0, min(q.z, h2))));
}
)";
const char* kRoundConeGlsl = R"(float sdRoundCone(vec3 p, float r1, float r2, float h) {
  vec2 q = vec2(length(p.xz), p.y);
  float b = (r1 - r2) / h, c = sqrt(1.0 - b * b);
  float along = dot(q, vec2(-b, c));
  if (along < 0.0) return length(q) - r1;
  if (along > c * h) return length(q - vec2(0.0, h)) - r2;
  return dot(q, vec2(c, b)) - r1;
}
)";
const char* kEllipsoidGlsl = R"(float sdEllipsoid(vec3 p, vec3 r) {
  return (length(p / r) - 1.0) * min(r.x, min(r.y, r.z));
}
)";

}  // namespace

bool Aabb::finite() const {
  return !empty() && glm::all(glm::lessThan(glm::abs(lo), dvec3(1e299))) &&
         glm::all(glm::lessThan(glm::abs(hi), dvec3(1e299)));
}

const std::vector<PrimitiveInfo>& primitiveCatalogue() {
  static const std::vector<PrimitiveInfo> catalogue = {
      {PrimitiveKind::Sphere, "sphere", {kRadius}, sphere, sphereBounds, "sdSphere", kSphereGlsl,
       true, "sphere of `radius` at the origin"},
      {PrimitiveKind::Box, "box",
       {{"size", ParamType::Vector, ParamRule::PositiveVector, false, {}},
        {"rounding", ParamType::Number, ParamRule::NonNegative, true, dvec3(0)}},
       box, boxBounds, "sdBox", kBoxGlsl, true, "box of full side lengths `size`, edges rounded by `rounding`"},
      {PrimitiveKind::Torus, "torus",
       {{"major", ParamType::Number, ParamRule::Positive, false, {}},
        {"minor", ParamType::Number, ParamRule::Positive, false, {}}},
       torus, torusBounds, "sdTorus", kTorusGlsl, true, "ring of radius `major` in the xz plane, tube radius `minor`"},
      {PrimitiveKind::Cylinder, "cylinder", {kRadius, kHeight}, cylinder, cylinderBounds,
       "sdCylinder", kCylinderGlsl, true, "cylinder along y, centred, full `height`"},
      {PrimitiveKind::Cone, "cone", {kRadius, kHeight}, cone, coneBounds, "sdCone", kConeGlsl,
       true, "cone with base `radius` at y = 0 and apex at y = `height`"},
      {PrimitiveKind::Plane, "plane",
       {{"normal", ParamType::Vector, ParamRule::NonZeroVector, true, dvec3(0, 1, 0)},
        {"offset", ParamType::Number, ParamRule::Any, true, dvec3(0)}},
       plane, planeBounds, "sdPlane", kPlaneGlsl, true, "half-space below dot(p, normal) = offset"},
      {PrimitiveKind::Capsule, "capsule", {kRadius, kHeight}, capsule, capsuleBounds,
       "sdCapsule", kCapsuleGlsl, true, "segment along y of length `height`, thickened by `radius`"},
      {PrimitiveKind::TriPrism, "prism",
       {{"size", ParamType::Number, ParamRule::Positive, false, {}},
        {"depth", ParamType::Number, ParamRule::Positive, false, {}}},
       triPrism, triPrismBounds, "sdTriPrism", kTriPrismGlsl, true,
       "equilateral triangle of side `size` (xy, apex up) extruded along z over `depth`"},
      {PrimitiveKind::HexPrism, "hexprism",
       {kRadius, {"depth", ParamType::Number, ParamRule::Positive, false, {}}},
       hexPrism, hexPrismBounds, "sdHexPrism", kHexPrismGlsl, true,
       "hexagon of inradius `radius` (xy) extruded along z over `depth`"},
      {PrimitiveKind::Menger, "menger",
       {{"level", ParamType::Number, ParamRule::NonNegative, false, {}},
        {"size", ParamType::Number, ParamRule::Positive, true, dvec3(1)}},
       menger, mengerBounds, "sdMenger", kMengerGlsl, false,
       "Menger sponge of `level` iterations in a cube of side `size`"},
      {PrimitiveKind::Octahedron, "octahedron", {kRadius}, octahedron, octahedronBounds,
       "sdOctahedron", kOctahedronGlsl, true, "octahedron |x| + |y| + |z| <= `radius`"},
      {PrimitiveKind::Pyramid, "pyramid",
       {{"size", ParamType::Number, ParamRule::Positive, false, {}}, kHeight},
       pyramid, pyramidBounds, "sdPyramid", kPyramidGlsl, true,
       "square base of side `size` on y = 0, apex at y = `height`"},
      {PrimitiveKind::RoundCone, "round_cone",
       {{"bottom", ParamType::Number, ParamRule::Positive, false, {}},
        {"top", ParamType::Number, ParamRule::Positive, false, {}}, kHeight},
       roundCone, roundConeBounds, "sdRoundCone", kRoundConeGlsl, true,
       "spheres of radius `bottom` at the origin and `top` at y = `height`, and the cone touching both"},
      {PrimitiveKind::Ellipsoid, "ellipsoid",
       {{"radii", ParamType::Vector, ParamRule::PositiveVector, false, {}}},
       ellipsoid, ellipsoidBounds, "sdEllipsoid", kEllipsoidGlsl, false,
       "ellipsoid of semi-axes `radii` (a distance bound)"},
      {PrimitiveKind::Circle, "circle", {kRadius}, circle, circleBounds, "sdCircle", kCircleGlsl, true,
       "2D profile: circle of `radius` at the origin (for extrude and revolve)", true},
      {PrimitiveKind::Rect, "rect",
       {{"size", ParamType::Vector2, ParamRule::PositiveVector, false, {}},
        {"rounding", ParamType::Number, ParamRule::NonNegative, true, dvec3(0)}},
       rect, rectBounds, "sdRect", kRectGlsl, true,
       "2D profile: rectangle of full side lengths `size` [x, y], corners rounded by `rounding`", true},
      {PrimitiveKind::Hexagon, "hexagon", {kRadius}, hexagon, hexagonBounds, "sdHexagon", kHexagonGlsl,
       true, "2D profile: regular hexagon of inradius `radius`, flat top and bottom", true},
      {PrimitiveKind::Polygon, "polygon",
       {{"points", ParamType::Points, ParamRule::Any, false, {}}},
       polygonUnused, polygonUnusedBounds, "sdPolygon", "", true,
       "2D profile: closed simple polygon through `points` [[x, y], ...] (3 to 64)", true},
  };
  return catalogue;
}

const PrimitiveInfo* findPrimitive(const std::string& name) {
  for (const PrimitiveInfo& p : primitiveCatalogue())
    if (name == p.name) return &p;
  return nullptr;
}

const PrimitiveInfo& primitiveInfo(PrimitiveKind kind) {
  for (const PrimitiveInfo& p : primitiveCatalogue())
    if (p.kind == kind) return p;
  return primitiveCatalogue()[0];
}

namespace {

// flatten: the primitive and its helpers are inlined into the loop, so the
// loop has no calls and may be vectorised; a second copy for x86-64-v3 (AVX2:
// four doubles a vector, floor as one instruction) is chosen at load time where
// the processor has it. FMA is never contracted (compiler/CMakeLists.txt), so
// both copies give the per-point functions' bits.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define SDFC_BLOCK_CLONES __attribute__((flatten, target_clones("default", "arch=x86-64-v3")))
#else
#define SDFC_BLOCK_CLONES __attribute__((flatten))
#endif
template <double (*F)(const double*, const dvec3&)>
SDFC_BLOCK_CLONES void distanceLoop(const double* a, const double* x, const double* y, const double* z, double* out, int n) {
  for (int i = 0; i < n; ++i) out[i] = F(a, dvec3(x[i], y[i], z[i]));
}

}  // namespace

BlockDistance blockDistance(PrimitiveKind kind) {
  switch (kind) {
    case PrimitiveKind::Sphere: return distanceLoop<sphere>;
    case PrimitiveKind::Box: return distanceLoop<box>;
    case PrimitiveKind::Torus: return distanceLoop<torus>;
    case PrimitiveKind::Cylinder: return distanceLoop<cylinder>;
    case PrimitiveKind::Cone: return distanceLoop<cone>;
    case PrimitiveKind::Plane: return distanceLoop<plane>;
    case PrimitiveKind::Capsule: return distanceLoop<capsule>;
    case PrimitiveKind::TriPrism: return distanceLoop<triPrism>;
    case PrimitiveKind::HexPrism: return distanceLoop<hexPrism>;
    case PrimitiveKind::Menger: return distanceLoop<menger>;
    case PrimitiveKind::Octahedron: return distanceLoop<octahedron>;
    case PrimitiveKind::Pyramid: return distanceLoop<pyramid>;
    case PrimitiveKind::RoundCone: return distanceLoop<roundCone>;
    case PrimitiveKind::Ellipsoid: return distanceLoop<ellipsoid>;
    case PrimitiveKind::Circle: return distanceLoop<circle>;
    case PrimitiveKind::Rect: return distanceLoop<rect>;
    case PrimitiveKind::Hexagon: return distanceLoop<hexagon>;
    case PrimitiveKind::Polygon: return nullptr;
  }
  return nullptr;
}

const char* box2Glsl() { return kBox2Glsl; }
const char* triangleGlsl() { return kTriangleGlsl; }

int flattenedParamCount(const PrimitiveInfo& info) {
  int n = 0;
  for (const ParamSpec& s : info.params)
    n += s.type == ParamType::Vector ? 3 : s.type == ParamType::Vector2 ? 2 : s.type == ParamType::Points ? 0 : 1;
  return n;
}

}  // namespace sdfc
