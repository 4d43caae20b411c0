#include "meshin/mesh_exact.h"

#include <cstdio>
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

// Two squared distances this close are a tie: the nearer face is then the one
// p is most nearly in front of (see the sign in meshExactGlsl).
constexpr double kTie = 1.0002;

}  // namespace

size_t meshExactBytes(const MeshDistance& mesh) {
  return (mesh.nodes().size() * 2 + mesh.triangleCount() * 3) * 16;
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
)";
}

std::string meshExactGlsl(const std::string& name, const MeshDistance& mesh, const MeshGridLayout& grid,
                          size_t grid_base, const MeshExactData& at, const std::string& visits,
                          const std::string& loop_zero, bool count) {
  const std::string g = std::to_string(grid_base), nb = std::to_string(at.nodes), tb = std::to_string(at.triangles);
  const std::string eb = glslNumber(grid.errorBound()), tie = glslNumber(kTie), untie = glslNumber(1 / kTie);
  const int stack = mesh.depth() + 1;
  auto box = [&](const std::string& i) {
    return "sdMeshBox2(p, sd_data[" + nb + " + 2 * " + i + "].xyz, sd_data[" + nb + " + 2 * " + i + " + 1].xyz)";
  };
  std::ostringstream o;
  o << "// A mesh of " << mesh.triangleCount() << " triangles, exact within " << glslNumber(kMeshExactNear)
    << " grid bounds (" << eb << ") of its surface:\n"
    << "// its hierarchy at sd_data[" << nb << "], triangles at sd_data[" << tb << "], grid at sd_data[" << g
    << "].\n";
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
  o << "  float best2 = cap * cap, side = 0.0;\n";
  o << "  int sn[" << stack << "];\n  float sd[" << stack << "], sm[" << stack << "];\n";
  o << "  sn[0] = 0;\n  sd[0] = " << box("0") << ";\n  sm[0] = sd[0];\n  int sp = 1;\n";
  o << "  for (int it = " << loop_zero << "; it < " << visits << " && sp > 0; it++) {\n";
  if (count) o << "    g_loop_iterations++;\n";
  o << "    sp--;\n    if (sd[sp] > best2 * " << tie << ") continue;\n";
  o << "    int ni = sn[sp];\n";
  o << "    int first = int(sd_data[" << nb << " + 2 * ni].w), count = int(sd_data[" << nb << " + 2 * ni + 1].w);\n";
  o << "    if (count == 0) {\n";
  o << "      int l = ni + 1, r = first;\n";
  o << "      float dl = " << box("l") << ", dr = " << box("r") << ";\n";
  o << "      bool left_near = dl <= dr;\n";
  o << "      int nn = left_near ? l : r, nf = left_near ? r : l;\n";
  o << "      float dn = min(dl, dr), df = max(dl, dr);\n";
  o << "      // The far child first, so the near one is visited next.\n";
  o << "      if (df <= best2 * " << tie << ") {\n";
  o << "        sn[sp] = nf;\n        sd[sp] = df;\n        sm[sp] = sp > 0 ? min(sm[sp - 1], df) : df;\n        sp++;\n      }\n";
  o << "      if (dn <= best2 * " << tie << ") {\n";
  o << "        sn[sp] = nn;\n        sd[sp] = dn;\n        sm[sp] = sp > 0 ? min(sm[sp - 1], dn) : dn;\n        sp++;\n      }\n";
  o << "    } else {\n";
  o << "      int t = " << tb << " + 3 * first;\n";
  for (unsigned j = 0; j < kMeshLeafSize; ++j) {
    o << "      if (" << j << " < count) {\n";
    o << "        vec4 a = sd_data[t + " << 3 * j << "], b = sd_data[t + " << 3 * j + 1 << "], c = sd_data[t + "
      << 3 * j + 2 << "];\n";
    o << "        float d2 = sdMeshTriangle2(p, a.xyz, b.xyz, c.xyz), h = dot(p - a.xyz, vec3(a.w, b.w, c.w));\n";
    o << "        // On a tie (a shared edge or corner) the face p is most in front of gives the side.\n";
    o << "        if (d2 < best2 * " << untie << " || (d2 <= best2 * " << tie << " && abs(h) > abs(side))) side = h;\n";
    o << "        best2 = min(best2, d2);\n";
    o << "      }\n";
  }
  o << "    }\n";
  o << "    // Drop entries no nearer than the best so far (straight-line code: no visits).\n";
  for (int j = 0; j < 3; ++j) o << "    if (sp > 0 && sd[sp - 1] > best2 * " << tie << ") sp--;\n";
  o << "  }\n";
  o << "  float d = sqrt(best2);\n";
  o << "  // Out of visits: the distance is between the least box left and the best so\n"
       "  // far; the grid's value, kept in that interval, is within its bound of it\n"
       "  // (the grid mode's step, where a bare lower bound could stall the march).\n";
  o << "  if (sp > 0) d = min(max(abs(g), sqrt(sm[sp - 1])), d);\n";
  o << "  // The grid's sign where it is sure (|g| above its error bound), else the nearest face's.\n";
  o << "  float s = abs(g) > " << eb << " ? g : side;\n";
  o << "  return s < 0.0 ? -d : d;\n}\n";
  return o.str();
}

}  // namespace sdfc
