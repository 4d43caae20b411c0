#include "mesh_quality.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <mutex>
#include <tuple>

#include "parallel.h"

namespace sdfc {
namespace {

// Zero area as the file holds it: the corners rounded to float32, and the
// least height no more than float32 resolves at those coordinates or a
// millionth of the longest edge (a sliver no slicer gives an area).
bool flatAsWritten(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
  a = glm::dvec3(glm::vec3(a)), b = glm::dvec3(glm::vec3(b)), c = glm::dvec3(glm::vec3(c));
  const double longest = std::max({glm::length(b - a), glm::length(c - b), glm::length(a - c)});
  if (longest == 0) return true;
  const double height = glm::length(glm::cross(b - a, c - a)) / longest;
  const glm::dvec3 m = glm::max(glm::abs(a), glm::max(glm::abs(b), glm::abs(c)));
  return height <= std::max(std::max({m.x, m.y, m.z}) * double(std::numeric_limits<float>::epsilon()),
                            1e-6 * longest);
}

}  // namespace

MeshTopology checkTopology(const TriangleMesh& mesh) {
  MeshTopology out;
  // Undirected edges with the direction each triangle walks them.
  struct HalfEdge {
    uint32_t lo, hi;
    bool forward;
    bool operator<(const HalfEdge& o) const { return std::tie(lo, hi) < std::tie(o.lo, o.hi); }
  };
  std::vector<HalfEdge> half;
  half.reserve(mesh.triangles.size() * 3);
  // The link of each vertex: the edge opposite it in every incident triangle.
  std::vector<std::array<uint32_t, 3>> link;
  link.reserve(mesh.triangles.size() * 3);
  for (const glm::uvec3& t : mesh.triangles) {
    const uint32_t v[3] = {t.x, t.y, t.z};
    for (int i = 0; i < 3; ++i) {
      const uint32_t a = v[i], b = v[(i + 1) % 3];
      half.push_back({std::min(a, b), std::max(a, b), a < b});
      link.push_back({v[i], v[(i + 1) % 3], v[(i + 2) % 3]});
    }
    if (t.x == t.y || t.y == t.z || t.x == t.z || flatAsWritten(mesh.positions[t.x], mesh.positions[t.y], mesh.positions[t.z]))
      ++out.degenerate_triangles;
  }
  std::sort(half.begin(), half.end());
  std::optional<glm::dvec3> first_boundary;
  for (size_t i = 0; i < half.size();) {
    size_t j = i;
    while (j < half.size() && half[j].lo == half[i].lo && half[j].hi == half[i].hi) ++j;
    const size_t uses = j - i;
    ++out.edges;
    if (uses == 1 && ++out.boundary_edges == 1) first_boundary = mesh.positions[half[i].lo];
    if (uses > 2) ++out.non_manifold_edges;
    if (uses > 2 && !out.problem_at) out.problem_at = 0.5 * (mesh.positions[half[i].lo] + mesh.positions[half[i].hi]);
    if (uses == 2 && half[i].forward == half[i + 1].forward) ++out.inconsistent_edges;
    i = j;
  }
  std::sort(link.begin(), link.end());
  // A vertex is manifold when its link edges form one path or cycle: every
  // link vertex has degree <= 2 and the link is connected.
  std::vector<uint32_t> ids, parent;
  std::vector<int> degree;
  for (size_t i = 0; i < link.size();) {
    size_t j = i;
    while (j < link.size() && link[j][0] == link[i][0]) ++j;
    ++out.vertices;
    ids.clear();
    for (size_t k = i; k < j; ++k) ids.insert(ids.end(), {link[k][1], link[k][2]});
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    parent.resize(ids.size());
    degree.assign(ids.size(), 0);
    for (size_t k = 0; k < ids.size(); ++k) parent[k] = uint32_t(k);
    auto find = [&](uint32_t x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    auto slot = [&](uint32_t v) { return uint32_t(std::lower_bound(ids.begin(), ids.end(), v) - ids.begin()); };
    size_t components = ids.size();
    bool ok = true;
    for (size_t k = i; k < j; ++k) {
      const uint32_t a = slot(link[k][1]), b = slot(link[k][2]);
      if (++degree[a] > 2 || ++degree[b] > 2) ok = false;
      const uint32_t ra = find(a), rb = find(b);
      if (ra != rb) parent[ra] = rb, --components;
    }
    if (!ok || components != 1) {
      ++out.non_manifold_vertices;
      if (!out.problem_at) out.problem_at = mesh.positions[link[i][0]];
    }
    i = j;
  }
  if (!out.problem_at) out.problem_at = first_boundary;
  out.euler = long(out.vertices) - long(out.edges) + long(mesh.triangles.size());
  return out;
}

double meshVolume(const TriangleMesh& mesh) {
  if (mesh.positions.empty()) return 0;
  // About the first vertex: smaller products, less cancellation.
  const glm::dvec3 o = mesh.positions[0];
  double six_v = 0;
  for (const glm::uvec3& t : mesh.triangles)
    six_v += glm::dot(mesh.positions[t.x] - o,
                      glm::cross(mesh.positions[t.y] - o, mesh.positions[t.z] - o));
  return six_v / 6;
}

double maxVertexError(const Evaluator& eval, const TriangleMesh& mesh, int threads) {
  std::mutex m;
  double worst = 0;
  parallelFor(mesh.positions.size(), 1024, threads, [&](size_t begin, size_t end, int) {
    double local = 0;
    for (size_t i = begin; i < end; ++i) local = std::max(local, std::fabs(eval.distance(mesh.positions[i])));
    std::lock_guard<std::mutex> lock(m);
    worst = std::max(worst, local);
  });
  return worst;
}

}  // namespace sdfc
