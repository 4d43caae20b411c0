#include "meshin/mesh_exact.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include "meshin/mesh_distance.h"
#include "meshin/mesh_grid.h"

namespace sdfc {
namespace {

std::string glslNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  std::string s = buf;
  if (s.find_first_of(".en") == std::string::npos) s += ".0";
  return s;
}

using Key = std::array<double, 3>;
Key key(const glm::dvec3& v) { return {v.x, v.y, v.z}; }

// The angle of triangle (a, b, c) at its corner a.
double cornerAngle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  const glm::dvec3 u = b - a, v = c - a;
  return std::atan2(glm::length(glm::cross(u, v)), glm::dot(u, v));
}

glm::dvec3 unit(const glm::dvec3& v) {
  const double l = glm::length(v);
  return l > 0 ? v / l : v;
}

}  // namespace

size_t meshExactBytes(const MeshDistance& mesh) {
  return (mesh.nodes().size() * 2 + mesh.triangleCount() * (3 + kMeshNormalVec4s)) * 16;
}

MeshExactData appendMeshExactData(const MeshDistance& mesh, std::vector<float>& data) {
  MeshExactData at;
  at.nodes = data.size() / 4;
  for (const MeshBvhNode& n : mesh.nodes()) {
    const float v[8] = {float(n.box.lo.x), float(n.box.lo.y), float(n.box.lo.z), float(n.first),
                        float(n.box.hi.x), float(n.box.hi.y), float(n.box.hi.z), float(n.count)};
    data.insert(data.end(), v, v + 8);
  }
  at.triangles = data.size() / 4;
  const std::vector<glm::dvec3>& c = mesh.corners();
  for (size_t t = 0; t < mesh.triangleCount(); ++t) {
    const glm::dvec3 n = glm::normalize(glm::cross(c[3 * t + 1] - c[3 * t], c[3 * t + 2] - c[3 * t]));
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3& p = c[3 * t + k];
      const float v[4] = {float(p.x), float(p.y), float(p.z), float(n[k])};
      data.insert(data.end(), v, v + 4);
    }
  }
  // The angle-weighted pseudo-normals (Baerentzen and Aanaes 2005) of each
  // triangle's corners and edges: at a corner the sum of its faces' normals,
  // each weighted by the face's angle there; at an edge the sum of its two
  // faces' normals. Corners and edges are matched by position (the mesh is
  // welded): the same point's normal is the same for every triangle at it.
  const size_t n_tri = mesh.triangleCount();
  std::vector<glm::dvec3> face(n_tri);
  std::map<Key, glm::dvec3> corner_sum;
  std::map<std::pair<Key, Key>, glm::dvec3> edge_sum;
  auto edgeKey = [](const glm::dvec3& u, const glm::dvec3& v) {
    const Key a = key(u), b = key(v);
    return a < b ? std::make_pair(a, b) : std::make_pair(b, a);
  };
  for (size_t t = 0; t < n_tri; ++t) {
    const glm::dvec3* q = &c[3 * t];
    face[t] = unit(glm::cross(q[1] - q[0], q[2] - q[0]));
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3 &a = q[k], &b = q[(k + 1) % 3], &d = q[(k + 2) % 3];
      corner_sum[key(a)] += cornerAngle(a, b, d) * face[t];
      edge_sum[edgeKey(a, b)] += face[t];
    }
  }
  at.normals = data.size() / 4;
  for (size_t t = 0; t < n_tri; ++t) {
    const glm::dvec3* q = &c[3 * t];
    glm::dvec3 v[3], e[3];
    for (int k = 0; k < 3; ++k) {
      v[k] = unit(corner_sum[key(q[k])]);
      e[k] = unit(edge_sum[edgeKey(q[k], q[(k + 1) % 3])]);
    }
    // 5 vec4: corners a, b, c with edge ab in their w; edges bc and ca.
    const float w[20] = {float(v[0].x), float(v[0].y), float(v[0].z), float(e[0].x),
                         float(v[1].x), float(v[1].y), float(v[1].z), float(e[0].y),
                         float(v[2].x), float(v[2].y), float(v[2].z), float(e[0].z),
                         float(e[1].x), float(e[1].y), float(e[1].z), 0.0f,
                         float(e[2].x), float(e[2].y), float(e[2].z), 0.0f};
    data.insert(data.end(), w, w + 20);
  }
  return at;
}

const char* meshExactHelperGlsl() {
  return R"(// The squared distance from p to triangle abc: to its plane where p projects
// inside it, else to the nearest of its edges (after Inigo Quilez's
// udTriangle, iquilezles.org/articles/distfunctions). No branches: the lanes
// of a SIMD group take both sides anyway.
float sdMeshSegment2(vec3 pa, vec3 e) {
  vec3 q = e * clamp(dot(e, pa) / dot(e, e), 0.0, 1.0) - pa;
  return dot(q, q);
}
float sdMeshTriangle2(vec3 p, vec3 a, vec3 b, vec3 c) {
  vec3 ab = b - a, bc = c - b, ca = a - c;
  vec3 pa = p - a, pb = p - b, pc = p - c;
  vec3 n = cross(ab, ca);
  bool inside = sign(dot(cross(ab, n), pa)) + sign(dot(cross(bc, n), pb)) + sign(dot(cross(ca, n), pc)) >= 2.0;
  float h = dot(n, pa);
  return inside ? h * h / dot(n, n)
                : min(min(sdMeshSegment2(pa, ab), sdMeshSegment2(pb, bc)), sdMeshSegment2(pc, ca));
}
float sdMeshBox2(vec3 p, vec3 lo, vec3 hi) {
  vec3 e = max(max(lo - p, p - hi), 0.0);
  return dot(e, e);
}
// The side of triangle t (its corners at sd_data[t], its pseudo-normals at
// sd_data[nt]) that p is on, when the triangle holds p's nearest point on the
// mesh: p minus its nearest feature (the face, an edge or a corner, by the
// regions of Ericson's "Real-Time Collision Detection" 5.1.5) dotted with
// that feature's angle-weighted pseudo-normal, positive outside (Baerentzen
// and Aanaes 2005: exact for a closed, consistently oriented mesh).
float sdMeshSide(vec3 p, int t, int nt) {
  vec4 a = sd_data[t], b = sd_data[t + 1], c = sd_data[t + 2];
  vec3 ab = b.xyz - a.xyz, ac = c.xyz - a.xyz, ap = p - a.xyz, bp = p - b.xyz, cp = p - c.xyz;
  float d1 = dot(ab, ap), d2 = dot(ac, ap), d3 = dot(ab, bp), d4 = dot(ac, bp), d5 = dot(ab, cp), d6 = dot(ac, cp);
  vec4 na = sd_data[nt], nb = sd_data[nt + 1], nc = sd_data[nt + 2];
  vec3 e_ab = vec3(na.w, nb.w, nc.w);
  if (d1 <= 0.0 && d2 <= 0.0) return dot(ap, na.xyz);
  if (d3 >= 0.0 && d4 <= d3) return dot(bp, nb.xyz);
  if (d6 >= 0.0 && d5 <= d6) return dot(cp, nc.xyz);
  if (d1 * d4 - d3 * d2 <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return dot(ap, e_ab);
  if (d5 * d2 - d1 * d6 <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return dot(ap, sd_data[nt + 4].xyz);
  if (d3 * d6 - d5 * d4 <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) return dot(bp, sd_data[nt + 3].xyz);
  return dot(ap, vec3(a.w, b.w, c.w));
}
)";
}

std::string meshExactGlsl(const std::string& name, const MeshDistance& mesh, const MeshGridLayout& grid,
                          size_t grid_base, const MeshExactData& at, const std::string& visits,
                          const std::string& loop_zero, bool count) {
  const std::string g = std::to_string(grid_base), nb = std::to_string(at.nodes), tb = std::to_string(at.triangles);
  const std::string nt = std::to_string(at.normals), eb = glslNumber(grid.errorBound());
  const int stack = mesh.depth() + 2;
  // Levels a visit descends (unrolled); deeper hierarchies go on in the next visit.
  const int descent = std::min(mesh.depth(), kMeshDescentLevels);
  auto box = [&](const std::string& i) {
    return "sdMeshBox2(p, sd_data[" + nb + " + 2 * " + i + "].xyz, sd_data[" + nb + " + 2 * " + i + " + 1].xyz)";
  };
  std::ostringstream o;
  o << "// A mesh of " << mesh.triangleCount() << " triangles, exact within " << glslNumber(kMeshExactNear)
    << " grid bounds (" << eb << ") of its surface:\n"
    << "// its hierarchy at sd_data[" << nb << "], triangles at sd_data[" << tb << "], their pseudo-normals at sd_data["
    << nt << "], grid at sd_data[" << g << "].\n";
  o << "float " << name << "(vec3 p) {\n";
  o << "  float g = sdMeshGrid(p, " << g << ");\n";
  o << "  vec4 h0 = sd_data[" << g << "], h1 = sd_data[" << g << " + 1];\n";
  o << "  // Outside the grid: the mesh box's distance, as the grid mode.\n";
  o << "  if (clamp(p, h0.xyz, h0.xyz + (h1.xyz - 1.0) * h0.w) != p) return g;\n";
  o << "  // Far from the surface: the grid less its error bound, a lower bound.\n";
  o << "  if (abs(g) > " << glslNumber(kMeshExactNear) << " * " << eb << ") return g > 0.0 ? g - " << eb
    << " : g + " << eb << ";\n";
  o << "  // The nearest triangle is within |g| + the bound: the search starts capped there.\n";
  o << "  float cap = abs(g) + " << glslNumber(1.05) << " * " << eb << ";\n";
  o << "  float best2 = cap * cap;\n  int bt = -1;\n";
  o << "  int sn[" << stack << "];\n  float sd[" << stack << "], sm[" << stack << "];\n";
  o << "  sn[0] = 0;\n  sd[0] = " << box("0") << ";\n  sm[0] = sd[0];\n  int sp = 1;\n";
  o << "  // A visit pops a box and descends from it to a leaf, nearer child first, the\n"
       "  // farther pushed (" << descent << " levels unrolled: straight-line code, one loop\n"
       "  // iteration), so a search near the surface takes a few visits, one a leaf:\n"
       "  // where the driver caps loops it is rationed to a handful.\n";
  o << "  for (int it = " << loop_zero << "; it < " << visits << " && sp > 0; it++) {\n";
  if (count) o << "    g_loop_iterations++;\n";
  o << "    sp--;\n    if (sd[sp] >= best2) continue;\n";
  o << "    int ni = sn[sp];\n    float dni = sd[sp];\n";
  o << "    vec4 lo = sd_data[" << nb << " + 2 * ni], hi = sd_data[" << nb << " + 2 * ni + 1];\n";
  for (int k = 0; k < descent; ++k) {
    o << "    if (ni >= 0 && hi.w == 0.0) {\n";
    o << "      int l = ni + 1, r = int(lo.w);\n";
    o << "      vec4 llo = sd_data[" << nb << " + 2 * l], lhi = sd_data[" << nb << " + 2 * l + 1];\n";
    o << "      vec4 rlo = sd_data[" << nb << " + 2 * r], rhi = sd_data[" << nb << " + 2 * r + 1];\n";
    o << "      float dl = sdMeshBox2(p, llo.xyz, lhi.xyz), dr = sdMeshBox2(p, rlo.xyz, rhi.xyz);\n";
    o << "      bool left_near = dl <= dr;\n";
    o << "      float dn = min(dl, dr), df = max(dl, dr);\n";
    o << "      if (df < best2) {\n";
    o << "        sn[sp] = left_near ? r : l;\n        sd[sp] = df;\n"
         "        sm[sp] = sp > 0 ? min(sm[sp - 1], df) : df;\n        sp++;\n      }\n";
    o << "      ni = dn < best2 ? (left_near ? l : r) : -1;\n";
    o << "      dni = dn;\n";
    o << "      lo = left_near ? llo : rlo;\n      hi = left_near ? lhi : rhi;\n";
    o << "    }\n";
  }
  o << "    if (ni >= 0 && hi.w == 0.0) {\n";
  o << "      // Deeper than the unrolled levels: back on the stack.\n";
  o << "      sn[sp] = ni;\n      sd[sp] = dni;\n      sm[sp] = sp > 0 ? min(sm[sp - 1], dni) : dni;\n      sp++;\n";
  o << "    } else if (ni >= 0) {\n";
  o << "      int first = int(lo.w), count = int(hi.w);\n";
  o << "      int t = " << tb << " + 3 * first;\n";
  for (unsigned j = 0; j < kMeshLeafSize; ++j) {
    o << "      if (" << j << " < count) {\n";
    o << "        float d2 = sdMeshTriangle2(p, sd_data[t + " << 3 * j << "].xyz, sd_data[t + " << 3 * j + 1
      << "].xyz, sd_data[t + " << 3 * j + 2 << "].xyz);\n";
    o << "        if (d2 < best2) {\n          best2 = d2;\n          bt = first + " << j << ";\n        }\n";
    o << "      }\n";
  }
  o << "    }\n";
  o << "    // Drop entries no nearer than the best so far (straight-line code: no visits).\n";
  for (int j = 0; j < 3; ++j) o << "    if (sp > 0 && sd[sp - 1] >= best2) sp--;\n";
  o << "  }\n";
  o << "  float d = sqrt(best2);\n";
  o << "  // The grid's sign where it is sure (|g| above its error bound), else the side\n"
       "  // of the nearest triangle's nearest feature by its pseudo-normal.\n";
  o << "  float s = abs(g) > " << eb << " ? g : (bt >= 0 ? sdMeshSide(p, " << tb << " + 3 * bt, " << nt
    << " + " << kMeshNormalVec4s << " * bt) : g);\n";
  o << "  if (sp > 0) {\n";
  o << "    // Out of visits (only where the driver caps loops): the distance is at least\n"
       "    // the least box left, and at least |g| less the grid's bound; a lower bound,\n"
       "    // that march() steps on but never stops on.\n";
  o << "    d = min(d, max(sqrt(sm[sp - 1]), abs(g) - " << eb << "));\n";
  if (count) o << "    g_bound_only = true;\n";
  o << "  }\n";
  o << "  return s < 0.0 ? -d : d;\n}\n";
  return o.str();
}

}  // namespace sdfc
