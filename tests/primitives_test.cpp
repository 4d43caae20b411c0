// The primitive catalogue's float64 distances, proved three ways:
//  (a) against closed forms written here independently (meridian-plane
//      polygons for solids of revolution, generic polygon distance plus an
//      extrusion for the prisms), to 1e-9;
//  (b) against brute force: the distance to a dense parametric sampling of
//      the surface, and the sign from an independent inside test;
//  (c) |gradient| = 1 wherever the nearest surface point is unique.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include "driver/compile.h"
#include "eval/evaluator.h"
#include "shapes/primitives.h"

namespace sdfc {
namespace {

using glm::dvec2;
using glm::dvec3;

constexpr double kPi = 3.14159265358979323846;

// ---- independent closed forms ----

double segmentDistance2(dvec2 p, dvec2 a, dvec2 b) {
  const dvec2 ab = b - a;
  double t = glm::dot(p - a, ab) / glm::dot(ab, ab);
  t = std::min(1.0, std::max(0.0, t));
  return glm::length(p - (a + t * ab));
}

// Inside by the crossing number (even-odd rule), not by edge orientation.
bool insidePolygon(dvec2 p, const std::vector<dvec2>& v) {
  bool in = false;
  for (size_t i = 0, j = v.size() - 1; i < v.size(); j = i++) {
    if ((v[i].y > p.y) != (v[j].y > p.y)) {
      const double x = v[j].x + (p.y - v[j].y) * (v[i].x - v[j].x) / (v[i].y - v[j].y);
      if (p.x < x) in = !in;
    }
  }
  return in;
}

// Signed distance to a simple polygon: nearest edge, sign from crossings.
double polygonDistance(dvec2 p, const std::vector<dvec2>& v) {
  double best = 1e300;
  for (size_t i = 0, j = v.size() - 1; i < v.size(); j = i++)
    best = std::min(best, segmentDistance2(p, v[j], v[i]));
  return insidePolygon(p, v) ? -best : best;
}

// Exact distance to the extrusion of a 2D set (signed distance a) over the
// slab |z| <= half (signed distance b): outside both, Pythagoras; otherwise
// the larger of the two.
double extrude(double a, double b) {
  if (a > 0 && b > 0) return std::hypot(a, b);
  if (a > 0) return a;
  if (b > 0) return b;
  return std::max(a, b);
}

std::vector<dvec2> regularPolygon(int n, double circumradius, double first_angle) {
  std::vector<dvec2> v;
  for (int i = 0; i < n; ++i) {
    const double a = first_angle + 2 * kPi * i / n;
    v.push_back(circumradius * dvec2(std::cos(a), std::sin(a)));
  }
  return v;
}

// Meridian coordinates of a solid of revolution about y: (rho, y).
dvec2 meridian(dvec3 p) { return {std::hypot(p.x, p.z), p.y}; }

double refSphere(const double* a, dvec3 p) { return std::sqrt(glm::dot(p, p)) - a[0]; }

// Rounded box = inner box (half extents minus rounding) grown by rounding.
double refBox(const double* a, dvec3 p) {
  const double r = a[3];
  const dvec3 inner = dvec3(a[0], a[1], a[2]) / 2.0 - r;
  const dvec3 nearest = glm::clamp(p, -inner, inner);
  const dvec3 d = p - nearest;
  if (d != dvec3(0)) return glm::length(d) - r;
  const dvec3 gap = inner - glm::abs(p);  // all >= 0 inside
  return -std::min({gap.x, gap.y, gap.z}) - r;
}

// Torus: the tube around the circle of radius major in the xz plane; for
// minor < major the meridian section is one disc.
double refTorus(const double* a, dvec3 p) {
  const double rho = std::hypot(p.x, p.z);
  if (rho == 0) return std::hypot(a[0], p.y) - a[1];
  const dvec3 on_circle = dvec3(p.x, 0, p.z) * (a[0] / rho);
  return glm::length(p - on_circle) - a[1];
}

// Cylinder: meridian section is the rectangle [-r, r] x [-h/2, h/2] (the
// mirrored half is part of it, so distances in the half-plane are exact).
double refCylinder(const double* a, dvec3 p) {
  const double r = a[0], h = a[1] / 2;
  return polygonDistance(meridian(p), {{-r, -h}, {r, -h}, {r, h}, {-r, h}});
}

// Cone: meridian section is the isosceles triangle (-r,0), (r,0), (0,h).
double refCone(const double* a, dvec3 p) {
  return polygonDistance(meridian(p), {{-a[0], 0}, {a[0], 0}, {0, a[1]}});
}

double refPlane(const double* a, dvec3 p) {
  const dvec3 n(a[0], a[1], a[2]);
  return glm::dot(p, n) / std::sqrt(glm::dot(n, n)) - a[3];
}

// Capsule: the points within radius of the y segment [-h/2, h/2].
double refCapsule(const double* a, dvec3 p) {
  const double h = a[1] / 2;
  const double y = std::min(h, std::max(-h, p.y));
  return glm::length(p - dvec3(0, y, 0)) - a[0];
}

// Triangle of side s: circumradius s / sqrt(3), vertex up, centroid at 0.
std::vector<dvec2> triangleVertices(double s) { return regularPolygon(3, s / std::sqrt(3.0), kPi / 2); }
// Hexagon of inradius r, flat top: vertices at 0, 60, ... degrees.
std::vector<dvec2> hexagonVertices(double r) { return regularPolygon(6, 2 * r / std::sqrt(3.0), 0); }

double refPrism(const double* a, dvec3 p) {
  return extrude(polygonDistance({p.x, p.y}, triangleVertices(a[0])), std::fabs(p.z) - a[1] / 2);
}
double refHexPrism(const double* a, dvec3 p) {
  return extrude(polygonDistance({p.x, p.y}, hexagonVertices(a[0])), std::fabs(p.z) - a[1] / 2);
}

// Menger: max(cube, -union of crosses), each cross measured in the cell the
// point lies in (the nearest copy of a centred square bar is always the own
// cell's one), with the square distance from the generic polygon code.
double refMenger(const double* a, dvec3 p) {
  const int level = static_cast<int>(a[0]);
  const double size = a[1];
  double d = refBox(std::vector<double>{size, size, size, 0}.data(), p);
  for (int k = 0; k < level; ++k) {
    const double cell = size / std::pow(3.0, k);
    const double w = cell / 6;
    const std::vector<dvec2> square = {{-w, -w}, {w, -w}, {w, w}, {-w, w}};
    dvec3 v;
    for (int i = 0; i < 3; ++i) v[i] = std::fmod(std::fmod(p[i] + size / 2, cell) + cell, cell) - cell / 2;
    const double cross = std::min({polygonDistance({v.y, v.z}, square),
                                   polygonDistance({v.z, v.x}, square),
                                   polygonDistance({v.x, v.y}, square)});
    d = std::max(d, -cross);
  }
  return d;
}


// ---- convex solids: signed distance from the support function ----

// A convex set K has signed distance max over unit u of (u . p - h_K(u)),
// h_K its support function, inside and outside alike. In 2D the maximum
// over the angle is found by a dense scan refined by golden sections.
double convexDistance2(dvec2 p, const std::function<double(dvec2)>& support) {
  auto g = [&](double a) {
    const dvec2 u(std::cos(a), std::sin(a));
    return glm::dot(u, p) - support(u);
  };
  const int n = 4096;
  int best = 0;
  for (int i = 1; i < n; ++i)
    if (g(2 * kPi * i / n) > g(2 * kPi * best / n)) best = i;
  double lo = 2 * kPi * (best - 1) / n, hi = 2 * kPi * (best + 1) / n;
  const double r = (std::sqrt(5.0) - 1) / 2;
  for (int it = 0; it < 80; ++it) {
    const double a = hi - r * (hi - lo), b = lo + r * (hi - lo);
    if (g(a) < g(b)) lo = a; else hi = b;
  }
  return g((lo + hi) / 2);
}

// Round cone: the meridian section is the convex hull of the discs of radius
// r1 at (0, 0) and r2 at (0, h), whose support is the larger of theirs.
double refRoundCone(const double* a, dvec3 p) {
  return convexDistance2(meridian(p), [a](dvec2 u) { return std::max(a[0], u.y * a[2] + a[1]); });
}

// Convex polytope given by its faces as triangles with outward order: inside,
// minus the nearest face plane; outside, the nearest face, each face by
// projection onto its plane when the foot falls inside it, else its edges.
double pointTriangle(dvec3 p, dvec3 a, dvec3 b, dvec3 c) {
  const dvec3 n = glm::normalize(glm::cross(b - a, c - a));
  const dvec3 foot = p - glm::dot(p - a, n) * n;
  auto side = [&](dvec3 x, dvec3 y) { return glm::dot(glm::cross(y - x, foot - x), n) >= 0; };
  if (side(a, b) && side(b, c) && side(c, a)) return std::fabs(glm::dot(p - a, n));
  auto seg = [&](dvec3 x, dvec3 y) {
    const double t = std::clamp(glm::dot(p - x, y - x) / glm::dot(y - x, y - x), 0.0, 1.0);
    return glm::length(p - (x + t * (y - x)));
  };
  return std::min({seg(a, b), seg(b, c), seg(c, a)});
}
using Triangle = std::array<dvec3, 3>;
double convexPolytope(dvec3 p, const std::vector<Triangle>& faces) {
  double plane = -1e300, surface = 1e300;
  for (const Triangle& t : faces) {
    const dvec3 n = glm::normalize(glm::cross(t[1] - t[0], t[2] - t[0]));
    plane = std::max(plane, glm::dot(p - t[0], n));
    surface = std::min(surface, pointTriangle(p, t[0], t[1], t[2]));
  }
  return plane <= 0 ? plane : surface;
}
std::vector<Triangle> octahedronFaces(double r) {
  std::vector<Triangle> faces;
  for (int i = 0; i < 8; ++i) {
    const dvec3 s((i & 1) ? -1 : 1, (i & 2) ? -1 : 1, (i & 4) ? -1 : 1);
    Triangle t = {dvec3(r * s.x, 0, 0), dvec3(0, r * s.y, 0), dvec3(0, 0, r * s.z)};
    if (s.x * s.y * s.z < 0) std::swap(t[1], t[2]);  // outward winding
    faces.push_back(t);
  }
  return faces;
}
std::vector<Triangle> pyramidFaces(double size, double h) {
  const double a = size / 2;
  const dvec3 apex(0, h, 0), c[4] = {{a, 0, a}, {a, 0, -a}, {-a, 0, -a}, {-a, 0, a}};
  std::vector<Triangle> faces;
  for (int i = 0; i < 4; ++i) faces.push_back({c[i], c[(i + 1) % 4], apex});
  faces.push_back({c[0], c[3], c[2]});
  faces.push_back({c[0], c[2], c[1]});
  return faces;
}
double refOctahedron(const double* a, dvec3 p) { return convexPolytope(p, octahedronFaces(a[0])); }
double refPyramid(const double* a, dvec3 p) { return convexPolytope(p, pyramidFaces(a[0], a[1])); }
// The ellipsoid is a bound: its reference is the bound as documented, and
// EllipsoidIsALowerBound checks it against the true surface.
double refEllipsoid(const double* a, dvec3 p) {
  const double k = std::sqrt(p.x * p.x / (a[0] * a[0]) + p.y * p.y / (a[1] * a[1]) + p.z * p.z / (a[2] * a[2]));
  return (k - 1) * std::min({a[0], a[1], a[2]});
}

// ---- independent inside tests ----

bool insideMenger(const double* a, dvec3 p) {
  const double size = a[1];
  for (int i = 0; i < 3; ++i)
    if (std::fabs(p[i]) >= size / 2) return false;
  dvec3 u = (p + size / 2) / size;  // in [0, 1)^3
  for (int k = 0; k < static_cast<int>(a[0]); ++k) {
    int ones = 0;
    for (int i = 0; i < 3; ++i) {
      u[i] *= 3;
      const double digit = std::floor(u[i]);
      u[i] -= digit;
      ones += digit == 1;
    }
    if (ones >= 2) return false;  // in a removed bar of this level
  }
  return true;
}

// ---- parametric surface sampling ----

struct Surface {
  std::vector<dvec3> points;
  double spacing = 0;  // largest distance between parametric neighbours
};

// Samples f(u, v), u, v in [0, 1], on an n x m grid.
void addPatch(Surface& s, int n, int m, const std::function<dvec3(double, double)>& f) {
  std::vector<dvec3> grid;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= m; ++j) grid.push_back(f(double(i) / n, double(j) / m));
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= m; ++j) {
      const dvec3 q = grid[i * (m + 1) + j];
      if (i < n) s.spacing = std::max(s.spacing, glm::length(grid[(i + 1) * (m + 1) + j] - q));
      if (j < m) s.spacing = std::max(s.spacing, glm::length(grid[i * (m + 1) + j + 1] - q));
    }
  s.points.insert(s.points.end(), grid.begin(), grid.end());
}

// A flat polygon face at z: grid points inside it (the edges are sampled by
// the side faces, so grid step is the spacing).
void addPolygonFace(Surface& s, const std::vector<dvec2>& v, double z, double step) {
  dvec2 lo(1e300), hi(-1e300);
  for (dvec2 q : v) lo = glm::min(lo, q), hi = glm::max(hi, q);
  for (double x = lo.x; x <= hi.x; x += step)
    for (double y = lo.y; y <= hi.y; y += step)
      if (insidePolygon({x, y}, v)) s.points.push_back({x, y, z});
  s.spacing = std::max(s.spacing, step * std::sqrt(2.0));
}

void addPrismSides(Surface& s, const std::vector<dvec2>& v, double half_depth, int n) {
  for (size_t i = 0, j = v.size() - 1; i < v.size(); j = i++) {
    const dvec2 a = v[j], b = v[i];
    addPatch(s, n, n / 2, [&](double u, double w) {
      const dvec2 q = a + (b - a) * u;
      return dvec3(q.x, q.y, -half_depth + 2 * half_depth * w);
    });
  }
  addPolygonFace(s, v, half_depth, 2 * half_depth / n * 2);
  addPolygonFace(s, v, -half_depth, 2 * half_depth / n * 2);
}

// A solid of revolution about y from a meridian polyline of (rho, y) points
// (each segment becomes a patch, sampled every `step` along the meridian).
void addRevolution(Surface& s, const std::vector<dvec2>& line, int n_around, double step) {
  for (size_t i = 0; i + 1 < line.size(); ++i) {
    const dvec2 a = line[i], b = line[i + 1];
    const int n_along = std::max(1, static_cast<int>(std::ceil(glm::length(b - a) / step)));
    addPatch(s, n_along, n_around, [&](double u, double w) {
      const dvec2 q = a + (b - a) * u;
      return dvec3(q.x * std::cos(2 * kPi * w), q.y, q.x * std::sin(2 * kPi * w));
    });
  }
}


// Triangles sampled as patches (one corner is the patch's degenerate edge).
void addTriangles(Surface& s, const std::vector<Triangle>& faces, int n) {
  for (const Triangle& t : faces)
    addPatch(s, n, n, [&](double u, double v) { return t[0] + u * (t[1] - t[0]) + u * v * (t[2] - t[1]); });
}

// ---- per primitive test setups ----

struct Case {
  const char* name;
  std::vector<double> args;
  double (*reference)(const double*, dvec3);
  std::function<bool(dvec3)> inside;  // null: sign checked against reference only
  std::function<Surface()> surface;   // null: no brute force
  double extent;                      // sampling box half size
};

std::vector<Case> cases() {
  std::vector<Case> out;
  out.push_back({"sphere", {0.8}, refSphere, [](dvec3 p) { return glm::length(p) < 0.8; },
                 [] {
                   Surface s;
                   addPatch(s, 300, 600, [](double u, double v) {
                     const double t = kPi * u, f = 2 * kPi * v;
                     return 0.8 * dvec3(std::sin(t) * std::cos(f), std::cos(t), std::sin(t) * std::sin(f));
                   });
                   return s;
                 },
                 1.5});
  for (double rounding : {0.0, 0.15}) {
    const dvec3 size(1.2, 0.7, 0.9);
    out.push_back({"box", {size.x, size.y, size.z, rounding}, refBox,
                   [=](dvec3 p) {
                     // Inside the rounded box: within `rounding` of the inner box.
                     const dvec3 inner = size / 2.0 - rounding;
                     const dvec3 q = glm::max(glm::abs(p) - inner, dvec3(0));
                     return rounding > 0 ? glm::length(q) < rounding : q == dvec3(0);
                   },
                   [=] {
                     Surface s;
                     const dvec3 h = size / 2.0 - rounding;
                     const int n = 200;
                     for (int a = 0; a < 3; ++a) {  // faces
                       const int b = (a + 1) % 3, c = (a + 2) % 3;
                       for (double sign : {-1.0, 1.0})
                         addPatch(s, n, n, [&](double u, double v) {
                           dvec3 q;
                           q[a] = sign * (h[a] + rounding);
                           q[b] = -h[b] + 2 * h[b] * u;
                           q[c] = -h[c] + 2 * h[c] * v;
                           return q;
                         });
                     }
                     if (rounding > 0) {
                       for (int c = 0; c < 3; ++c)  // edges: quarter cylinders along axis c
                         for (double sa : {-1.0, 1.0})
                           for (double sb : {-1.0, 1.0}) {
                             const int a = (c + 1) % 3, b = (c + 2) % 3;
                             addPatch(s, 40, n, [&](double u, double v) {
                               const double t = kPi / 2 * u;
                               dvec3 q;
                               q[a] = sa * (h[a] + rounding * std::cos(t));
                               q[b] = sb * (h[b] + rounding * std::sin(t));
                               q[c] = -h[c] + 2 * h[c] * v;
                               return q;
                             });
                           }
                       for (double sx : {-1.0, 1.0})  // corners: sphere octants
                         for (double sy : {-1.0, 1.0})
                           for (double sz : {-1.0, 1.0})
                             addPatch(s, 40, 40, [&](double u, double v) {
                               const double t = kPi / 2 * u, f = kPi / 2 * v;
                               return dvec3(sx * (h.x + rounding * std::sin(t) * std::cos(f)),
                                            sy * (h.y + rounding * std::sin(t) * std::sin(f)),
                                            sz * (h.z + rounding * std::cos(t)));
                             });
                     }
                     return s;
                   },
                   1.2});
  }
  out.push_back({"torus", {0.9, 0.3}, refTorus,
                 [](dvec3 p) {
                   const double rho = std::hypot(p.x, p.z);
                   return (rho - 0.9) * (rho - 0.9) + p.y * p.y < 0.09;
                 },
                 [] {
                   Surface s;
                   addPatch(s, 600, 200, [](double u, double v) {
                     const double f = 2 * kPi * u, t = 2 * kPi * v;
                     const double rho = 0.9 + 0.3 * std::cos(t);
                     return dvec3(rho * std::cos(f), 0.3 * std::sin(t), rho * std::sin(f));
                   });
                   return s;
                 },
                 1.5});
  out.push_back({"cylinder", {0.5, 1.4}, refCylinder,
                 [](dvec3 p) { return std::hypot(p.x, p.z) < 0.5 && std::fabs(p.y) < 0.7; },
                 [] {
                   Surface s;
                   addRevolution(s, {{0, -0.7}, {0.5, -0.7}, {0.5, 0.7}, {0, 0.7}}, 400, 0.006);
                   return s;
                 },
                 1.3});
  out.push_back({"cone", {0.6, 1.1}, refCone,
                 [](dvec3 p) { return p.y > 0 && std::hypot(p.x, p.z) < 0.6 * (1 - p.y / 1.1); },
                 [] {
                   Surface s;
                   addRevolution(s, {{0, 0}, {0.6, 0}, {0, 1.1}}, 400, 0.006);
                   return s;
                 },
                 1.3});
  out.push_back({"plane", {0.3, 1.0, -0.5, 0.2}, refPlane,
                 [](dvec3 p) { return glm::dot(p, glm::normalize(dvec3(0.3, 1, -0.5))) < 0.2; },
                 [] {
                   // A square of the plane large enough to hold the nearest
                   // point of every test point (|p| < 1).
                   Surface s;
                   const dvec3 n = glm::normalize(dvec3(0.3, 1, -0.5));
                   const dvec3 t1 = glm::normalize(glm::cross(n, dvec3(1, 0, 0)));
                   const dvec3 t2 = glm::cross(n, t1);
                   addPatch(s, 400, 400, [&](double u, double v) {
                     return 0.2 * n + (u * 4 - 2) * t1 + (v * 4 - 2) * t2;
                   });
                   return s;
                 },
                 1.0});
  out.push_back({"capsule", {0.35, 1.0}, refCapsule,
                 [](dvec3 p) {
                   const double y = std::clamp(p.y, -0.5, 0.5);
                   return glm::length(p - dvec3(0, y, 0)) < 0.35;
                 },
                 [] {
                   Surface s;
                   addRevolution(s, {{0.35, -0.5}, {0.35, 0.5}}, 400, 0.006);
                   for (double sign : {-1.0, 1.0})  // hemispheres, by angle (not chords)
                     addPatch(s, 60, 400, [&](double u, double v) {
                       const double t = kPi / 2 * u, f = 2 * kPi * v;
                       return dvec3(0.35 * std::sin(t) * std::cos(f), sign * (0.5 + 0.35 * std::cos(t)),
                                    0.35 * std::sin(t) * std::sin(f));
                     });
                   return s;
                 },
                 1.2});
  out.push_back({"prism", {1.0, 0.6}, refPrism,
                 [](dvec3 p) {
                   // Below the three edge lines (inward normals at 90+120k degrees).
                   if (std::fabs(p.z) >= 0.3) return false;
                   const double inradius = 1.0 / (2 * std::sqrt(3.0));
                   for (int k = 0; k < 3; ++k) {
                     const double a = -kPi / 2 + 2 * kPi * k / 3;
                     if (p.x * std::cos(a) + p.y * std::sin(a) >= inradius) return false;
                   }
                   return true;
                 },
                 [] {
                   Surface s;
                   addPrismSides(s, triangleVertices(1.0), 0.3, 300);
                   return s;
                 },
                 1.0});
  out.push_back({"hexprism", {0.5, 0.8}, refHexPrism,
                 [](dvec3 p) {
                   return std::fabs(p.z) < 0.4 && std::fabs(p.y) < 0.5 &&
                          std::sqrt(3.0) / 2 * std::fabs(p.x) + 0.5 * std::fabs(p.y) < 0.5;
                 },
                 [] {
                   Surface s;
                   addPrismSides(s, hexagonVertices(0.5), 0.4, 300);
                   return s;
                 },
                 1.2});
  for (double level : {0.0, 2.0, 3.0}) {
    const std::vector<double> a = {level, 1.5};
    out.push_back({"menger", a, refMenger, [a](dvec3 p) { return insideMenger(a.data(), p); },
                   nullptr, 1.2});
  }
  out.push_back({"octahedron", {0.9}, refOctahedron,
                 [](dvec3 p) { return std::fabs(p.x) + std::fabs(p.y) + std::fabs(p.z) < 0.9; },
                 [] {
                   Surface s;
                   addTriangles(s, octahedronFaces(0.9), 120);
                   return s;
                 },
                 1.3});
  out.push_back({"pyramid", {1.2, 0.9}, refPyramid,
                 [](dvec3 p) {
                   const double w = 0.6 * (1 - p.y / 0.9);
                   return p.y > 0 && p.y < 0.9 && std::fabs(p.x) < w && std::fabs(p.z) < w;
                 },
                 [] {
                   Surface s;
                   addTriangles(s, pyramidFaces(1.2, 0.9), 160);
                   return s;
                 },
                 1.2});
  for (const std::vector<double>& a : {std::vector<double>{0.5, 0.2, 0.8}, std::vector<double>{0.15, 0.4, 0.6}}) {
    out.push_back({"round_cone", a, refRoundCone,
                   [a](dvec3 p) {
                     // In one of the spheres, or in the frustum between their tangent circles.
                     const dvec2 q = meridian(p);
                     if (glm::length(q) < a[0] || glm::length(q - dvec2(0, a[2])) < a[1]) return true;
                     const double b = (a[0] - a[1]) / a[2], c = std::sqrt(1 - b * b);
                     const dvec2 t1 = a[0] * dvec2(c, b), t2 = dvec2(0, a[2]) + a[1] * dvec2(c, b);
                     return insidePolygon(q, {{-t1.x, t1.y}, t1, t2, {-t2.x, t2.y}});
                   },
                   [a] {
                     // The meridian: the bottom arc, the tangent segment, the top arc.
                     const double b = (a[0] - a[1]) / a[2], tangent = std::asin(b);
                     std::vector<dvec2> line;
                     for (int i = 0; i <= 200; ++i) {
                       const double t = -kPi / 2 + (tangent + kPi / 2) * i / 200;
                       line.push_back(a[0] * dvec2(std::cos(t), std::sin(t)));
                     }
                     for (int i = 0; i <= 200; ++i) {
                       const double t = tangent + (kPi / 2 - tangent) * i / 200;
                       line.push_back(dvec2(0, a[2]) + a[1] * dvec2(std::cos(t), std::sin(t)));
                     }
                     Surface s;
                     addRevolution(s, line, 400, 0.006);
                     return s;
                   },
                   1.3});
  }
  out.push_back({"ellipsoid", {0.9, 0.5, 0.7}, refEllipsoid,
                 [](dvec3 p) { return glm::length(p / dvec3(0.9, 0.5, 0.7)) < 1; }, nullptr, 1.3});
  return out;
}

// Random points: uniform in the box, plus points near the sampled surface.
std::vector<dvec3> testPoints(const Case& c, const Surface* surface, int count, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<dvec3> pts;
  for (int i = 0; i < count; ++i) {
    if (surface && i % 2 == 1) {
      // Near a surface sample inside the box (the plane's patch is larger).
      dvec3 s;
      do s = surface->points[rng() % surface->points.size()];
      while (glm::any(glm::greaterThan(glm::abs(s), dvec3(c.extent))));
      pts.push_back(s + 0.05 * c.extent * dvec3(u(rng), u(rng), u(rng)));
    } else {
      pts.push_back(c.extent * dvec3(u(rng), u(rng), u(rng)));
    }
  }
  return pts;
}

double catalogueDistance(const Case& c, dvec3 p) {
  return findPrimitive(c.name)->distance(c.args.data(), p);
}

TEST(Primitives, CatalogueHasEveryCase) {
  for (const PrimitiveInfo& info : primitiveCatalogue()) {
    if (info.profile) continue;  // 2D, only under extrude/revolve: tests/profiles_test.cpp
    bool found = false;
    for (const Case& c : cases()) found |= info.name == std::string(c.name);
    EXPECT_TRUE(found) << info.name << " has no test case";
  }
}

TEST(Primitives, AgreeWithIndependentClosedForms) {
  std::mt19937_64 rng(7);
  for (const Case& c : cases()) {
    const Surface surface = c.surface ? c.surface() : Surface{};
    const std::vector<dvec3> pts = testPoints(c, c.surface ? &surface : nullptr, 4000, rng);
    int inside = 0;
    for (const dvec3& p : pts) {
      const double d = catalogueDistance(c, p), ref = c.reference(c.args.data(), p);
      ASSERT_NEAR(d, ref, 1e-9 * std::max(1.0, std::fabs(ref)))
          << c.name << " at (" << p.x << ", " << p.y << ", " << p.z << ")";
      inside += d < 0;
    }
    // The sampling really covers both sides.
    if (std::string(c.name) != "plane") {
      EXPECT_GT(inside, 200) << c.name;
    }
    EXPECT_LT(inside, 3800) << c.name;
  }
}

TEST(Primitives, SignMatchesIndependentInsideTest) {
  std::mt19937_64 rng(11);
  for (const Case& c : cases()) {
    const Surface surface = c.surface ? c.surface() : Surface{};
    for (const dvec3& p : testPoints(c, c.surface ? &surface : nullptr, 4000, rng)) {
      const double d = catalogueDistance(c, p);
      if (std::fabs(d) < 1e-12) continue;  // on the surface either answer is right
      EXPECT_EQ(d < 0, c.inside(p)) << c.name << " (level/args " << c.args[0] << ") at (" << p.x
                                     << ", " << p.y << ", " << p.z << "), d = " << d;
    }
  }
}

// |d| is the distance to the surface: never more than the distance to any
// surface sample, and at most the sampling spacing less than the nearest one.
TEST(Primitives, MatchBruteForceSurfaceDistance) {
  std::mt19937_64 rng(13);
  for (const Case& c : cases()) {
    if (!c.surface) continue;
    const Surface surface = c.surface();
    ASSERT_LT(surface.spacing, 0.02) << c.name;
    double worst = 0;
    for (const dvec3& p : testPoints(c, &surface, 200, rng)) {
      double nearest = 1e300;
      for (const dvec3& s : surface.points) nearest = std::min(nearest, glm::length(p - s));
      const double d = std::fabs(catalogueDistance(c, p));
      ASSERT_LE(d, nearest + 1e-12) << c.name << " at (" << p.x << ", " << p.y << ", " << p.z << ")";
      ASSERT_GE(d, nearest - surface.spacing)
          << c.name << " at (" << p.x << ", " << p.y << ", " << p.z << ")";
      worst = std::max(worst, nearest - d);
    }
    EXPECT_LE(worst, surface.spacing) << c.name;
  }
}

// Exact distances have unit gradient wherever the nearest point is unique;
// on the medial axis and at creases a central difference averages two unit
// vectors, so it is shorter, never longer. Bounds (menger) are 1-Lipschitz.
TEST(Primitives, GradientHasUnitLengthAwayFromMedialAxis) {
  std::mt19937_64 rng(17);
  for (const Case& c : cases()) {
    const PrimitiveInfo& info = *findPrimitive(c.name);
    const double h = 1e-6;
    int off_unit = 0;
    const std::vector<dvec3> pts = testPoints(c, nullptr, 3000, rng);
    for (const dvec3& p : pts) {
      dvec3 g;
      for (int a = 0; a < 3; ++a) {
        dvec3 e(0);
        e[a] = h;
        g[a] = (catalogueDistance(c, p + e) - catalogueDistance(c, p - e)) / (2 * h);
      }
      const double len = glm::length(g);
      ASSERT_LE(len, 1 + 1e-6) << c.name << " at (" << p.x << ", " << p.y << ", " << p.z << ")";
      off_unit += std::fabs(len - 1) > 1e-6;
    }
    if (info.exact) {
      EXPECT_LT(off_unit, 30) << c.name;  // under 1%: only points within h of a crease
    }
  }
}

TEST(Primitives, OnlyMengerAndEllipsoidAreBounds) {
  for (const PrimitiveInfo& info : primitiveCatalogue())
    EXPECT_EQ(info.exact, info.kind != PrimitiveKind::Menger && info.kind != PrimitiveKind::Ellipsoid)
        << info.name;
}

// The ellipsoid's bound never exceeds the distance to its surface (sampled
// densely by angle), has the right sign, equals the sphere's distance when
// the radii agree, and is within min/max(radii) of the truth.
TEST(Primitives, EllipsoidIsALowerBound) {
  const double r[3] = {0.9, 0.35, 0.6};
  Surface s;
  addPatch(s, 600, 1200, [&](double u, double v) {
    const double t = kPi * u, f = 2 * kPi * v;
    return dvec3(r[0] * std::sin(t) * std::cos(f), r[1] * std::cos(t), r[2] * std::sin(t) * std::sin(f));
  });
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> u(-1.4, 1.4);
  double tightest = 1;
  for (int i = 0; i < 400; ++i) {
    const dvec3 p(u(rng), u(rng), u(rng));
    double nearest = 1e300;
    for (const dvec3& q : s.points) nearest = std::min(nearest, glm::length(p - q));
    const double d = findPrimitive("ellipsoid")->distance(r, p);
    ASSERT_LE(std::fabs(d), nearest + 1e-12) << p.x << " " << p.y << " " << p.z;
    ASSERT_EQ(d < 0, glm::length(p / dvec3(r[0], r[1], r[2])) < 1);
    if (nearest > 0.05) tightest = std::min(tightest, std::fabs(d) / nearest);
  }
  EXPECT_GE(tightest, 0.35 / 0.9 - 0.01);
  const double same[3] = {0.7, 0.7, 0.7}, radius = 0.7;
  for (int i = 0; i < 100; ++i) {
    const dvec3 p(u(rng), u(rng), u(rng));
    EXPECT_NEAR(findPrimitive("ellipsoid")->distance(same, p), findPrimitive("sphere")->distance(&radius, p), 1e-15);
  }
}

// The .sdf spelling reaches the same function with the parameters in the
// documented order (args are flattened by the checker).
TEST(Primitives, SceneTextEvaluatesTheSamePrimitive) {
  const struct {
    const char* text;
    const char* name;
    std::vector<double> args;
  } scenes[] = {
      {"sphere(radius: 0.8)", "sphere", {0.8}},
      {"box(size: [1.2, 0.7, 0.9], rounding: 0.15)", "box", {1.2, 0.7, 0.9, 0.15}},
      {"torus(major: 0.9, minor: 0.3)", "torus", {0.9, 0.3}},
      {"cylinder(radius: 0.5, height: 1.4)", "cylinder", {0.5, 1.4}},
      {"cone(radius: 0.6, height: 1.1)", "cone", {0.6, 1.1}},
      {"plane(normal: [0.3, 1, -0.5], offset: 0.2)", "plane", {0.3, 1, -0.5, 0.2}},
      {"capsule(radius: 0.35, height: 1)", "capsule", {0.35, 1}},
      {"prism(size: 1, depth: 0.6)", "prism", {1, 0.6}},
      {"hexprism(radius: 0.5, depth: 0.8)", "hexprism", {0.5, 0.8}},
      {"menger(level: 2, size: 1.5)", "menger", {2, 1.5}},
      {"octahedron(radius: 0.9)", "octahedron", {0.9}},
      {"pyramid(size: 1.2, height: 0.9)", "pyramid", {1.2, 0.9}},
      {"round_cone(bottom: 0.5, top: 0.2, height: 0.8)", "round_cone", {0.5, 0.2, 0.8}},
      {"ellipsoid(radii: [0.9, 0.5, 0.7])", "ellipsoid", {0.9, 0.5, 0.7}},
  };
  std::mt19937_64 rng(19);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  for (const auto& s : scenes) {
    Diagnostics diags;
    CompiledScene compiled =
        checkSource("t.sdf", std::string("scene { ") + s.text + " }\n", {}, diags);
    ASSERT_TRUE(compiled.ok) << diags.format();
    const Evaluator eval(compiled.scene);
    for (int i = 0; i < 500; ++i) {
      const dvec3 p(u(rng), u(rng), u(rng));
      ASSERT_EQ(eval.distance(p), findPrimitive(s.name)->distance(s.args.data(), p)) << s.text;
    }
  }
}

// The seed paper's cylinder, max(length(p.xy) - r, |p.y| - h/2), measures the
// radius in the wrong plane: on the z axis outside the cylinder it says inside.
TEST(Primitives, SeedPaperCylinderIsWrong) {
  const double args[] = {0.5, 1.4};
  const dvec3 p(0, 0, 1.0);
  const double paper = std::max(std::hypot(p.x, p.y) - 0.5, std::fabs(p.y) - 0.7);
  EXPECT_LT(paper, 0);
  EXPECT_NEAR(findPrimitive("cylinder")->distance(args, p), 0.5, 1e-15);
}

}  // namespace
}  // namespace sdfc
