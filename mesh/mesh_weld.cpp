#include "mesh_weld.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <tuple>

namespace sdfc {
namespace {

using glm::dvec3;

struct UnionFind {
  std::vector<uint32_t> parent;
  explicit UnionFind(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  uint32_t find(uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  // The smaller index stays the representative, so the result does not
  // depend on the order pairs are met in.
  void join(uint32_t a, uint32_t b) {
    a = find(a), b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

// Twice the area over the longest edge: the triangle's least height.
double leastHeight(const dvec3& a, const dvec3& b, const dvec3& c) {
  const double longest = std::max({glm::length(b - a), glm::length(c - b), glm::length(a - c)});
  return longest > 0 ? glm::length(glm::cross(b - a, c - a)) / longest : 0;
}

uint64_t edgeKey(uint32_t a, uint32_t b) { return uint64_t(std::min(a, b)) << 32 | std::max(a, b); }

// Merges every pair of vertices within `tolerance` (max-norm), found
// through a hash grid of four times that spacing: a neighbour cell along an
// axis is looked at only when the point is within `tolerance` of that side,
// so most points look at their own cell alone.
std::vector<uint32_t> clusterVertices(const std::vector<dvec3>& positions, double tolerance,
                                      size_t* merged) {
  const size_t n = positions.size();
  const double spacing = 4 * tolerance;
  using Cell = std::array<int64_t, 3>;
  auto cellOf = [&](const dvec3& p) {
    return Cell{int64_t(std::floor(p.x / spacing)), int64_t(std::floor(p.y / spacing)),
                int64_t(std::floor(p.z / spacing))};
  };
  std::vector<std::pair<Cell, uint32_t>> sorted(n);
  for (size_t i = 0; i < n; ++i) sorted[i] = {cellOf(positions[i]), uint32_t(i)};
  std::sort(sorted.begin(), sorted.end());
  UnionFind uf(n);
  for (size_t i = 0; i < n; ++i) {
    const auto& [cell, v] = sorted[i];
    const dvec3 p = positions[v];
    int lo[3], hi[3];
    for (int d = 0; d < 3; ++d) {
      const double offset = p[d] - double(cell[size_t(d)]) * spacing;
      lo[d] = offset <= tolerance ? -1 : 0;
      hi[d] = offset >= spacing - tolerance ? 1 : 0;
    }
    // Each pair is looked at once: from the smaller cell, or in one cell by index.
    for (int dz = lo[2]; dz <= hi[2]; ++dz)
      for (int dy = lo[1]; dy <= hi[1]; ++dy)
        for (int dx = lo[0]; dx <= hi[0]; ++dx) {
          const Cell other{cell[0] + dx, cell[1] + dy, cell[2] + dz};
          if (other < cell) continue;
          auto it = other == cell ? sorted.begin() + ptrdiff_t(i) + 1
                                  : std::lower_bound(sorted.begin(), sorted.end(), std::make_pair(other, uint32_t(0)));
          for (; it != sorted.end() && it->first == other; ++it) {
            const dvec3 d = glm::abs(positions[it->second] - p);
            if (std::max({d.x, d.y, d.z}) <= tolerance) uf.join(v, it->second);
          }
        }
  }
  std::vector<uint32_t> rep(n);
  size_t count = 0;
  for (size_t i = 0; i < n; ++i) {
    rep[i] = uf.find(uint32_t(i));
    if (rep[i] != i) ++count;
  }
  if (merged) *merged = count;
  return rep;
}

}  // namespace

double weldTolerance(const TriangleMesh& mesh, double voxel) {
  double largest = 0;
  for (const dvec3& p : mesh.positions)
    largest = std::max({largest, std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
  // Four float32 ulps at the largest coordinate: two points that round to
  // one float32 are always merged, and two kept apart never round together.
  const double float_step = 4.0 * largest * double(std::numeric_limits<float>::epsilon());
  return std::max(1e-4 * voxel, float_step);
}

WeldStats weldByPosition(TriangleMesh& mesh, double tolerance) {
  WeldStats stats;
  const std::vector<uint32_t> rep = clusterVertices(mesh.positions, tolerance, &stats.merged_vertices);

  // 1. Remap, dropping triangles with two corners at one point.
  std::vector<glm::uvec3> tris;
  std::vector<int> materials;
  tris.reserve(mesh.triangles.size());
  materials.reserve(mesh.triangles.size());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const glm::uvec3 tri(rep[mesh.triangles[t].x], rep[mesh.triangles[t].y], rep[mesh.triangles[t].z]);
    if (tri.x == tri.y || tri.y == tri.z || tri.z == tri.x) {
      ++stats.collapsed_triangles;
      continue;
    }
    tris.push_back(tri);
    materials.push_back(mesh.materials.empty() ? -1 : mesh.materials[t]);
  }

  // 2. Fins: two triangles on the same three corners wound oppositely
  // enclose nothing (a collapsed quad folded onto its neighbour); drop both.
  {
    struct Entry {
      std::array<uint32_t, 3> sorted;
      bool even;  // winding parity relative to the sorted order
      size_t index;
    };
    std::vector<Entry> entries(tris.size());
    for (size_t t = 0; t < tris.size(); ++t) {
      std::array<uint32_t, 3> v{tris[t].x, tris[t].y, tris[t].z};
      // Rotate the smallest index first; the parity is then which way the other two go.
      const int first = int(std::min_element(v.begin(), v.end()) - v.begin());
      std::rotate(v.begin(), v.begin() + first, v.end());
      const bool even = v[1] < v[2];
      if (!even) std::swap(v[1], v[2]);
      entries[t] = {v, even, t};
    }
    std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
      return std::tie(a.sorted, a.even, a.index) < std::tie(b.sorted, b.even, b.index);
    });
    std::vector<bool> drop(tris.size(), false);
    for (size_t i = 0; i < entries.size();) {
      size_t j = i;
      while (j < entries.size() && entries[j].sorted == entries[i].sorted) ++j;
      // Pair off opposite windings within the group.
      std::vector<size_t> even, odd;
      for (size_t k = i; k < j; ++k) (entries[k].even ? even : odd).push_back(entries[k].index);
      const size_t pairs = std::min(even.size(), odd.size());
      for (size_t k = 0; k < pairs; ++k) drop[even[k]] = drop[odd[k]] = true;
      stats.fin_triangles += 2 * pairs;
      i = j;
    }
    if (stats.fin_triangles) {
      size_t out = 0;
      for (size_t t = 0; t < tris.size(); ++t)
        if (!drop[t]) tris[out] = tris[t], materials[out] = materials[t], ++out;
      tris.resize(out);
      materials.resize(out);
    }
  }

  // 3. Zero-area triangles with three distinct corners (b on the segment a-c):
  // flip a-c with the triangle across it, (a, b, c) + (a, c, d) -> (a, b, d) +
  // (b, c, d). The two new triangles tile the same region, so the surface
  // does not move. Skipped where b-d is already an edge (that would make it
  // non-manifold) or a-c is not shared by exactly two triangles.
  {
    auto isFlat = [&](const glm::uvec3& t) {
      return leastHeight(mesh.positions[t.x], mesh.positions[t.y], mesh.positions[t.z]) <= tolerance;
    };
    std::vector<size_t> flat;
    for (size_t t = 0; t < tris.size(); ++t)
      if (isFlat(tris[t])) flat.push_back(t);
    if (!flat.empty()) {
      // Edge -> triangles using it, rebuilt lazily: flats are rare.
      std::vector<std::pair<uint64_t, uint32_t>> uses;
      auto rebuild = [&] {
        uses.clear();
        uses.reserve(tris.size() * 3);
        for (size_t t = 0; t < tris.size(); ++t)
          for (int c = 0; c < 3; ++c) uses.push_back({edgeKey(tris[t][c], tris[t][(c + 1) % 3]), uint32_t(t)});
        std::sort(uses.begin(), uses.end());
      };
      auto usersOf = [&](uint64_t key) {
        auto lo = std::lower_bound(uses.begin(), uses.end(), std::make_pair(key, uint32_t(0)));
        std::vector<uint32_t> out;
        for (; lo != uses.end() && lo->first == key; ++lo) out.push_back(lo->second);
        return out;
      };
      // A flip can leave a new flat triangle (d on the same line); a few rounds settle it.
      for (int round = 0; round < 8 && !flat.empty(); ++round) {
        rebuild();
        std::vector<bool> touched(tris.size(), false);
        std::vector<uint64_t> made;  // edges this round's flips created (not in `uses` yet)
        std::vector<size_t> still;
        for (size_t t : flat) {
          if (touched[t] || !isFlat(tris[t])) continue;
          // Rotate so (a, b, c) has a-c as the longest edge: b opposite it.
          glm::uvec3 tri = tris[t];
          const dvec3* p = mesh.positions.data();
          int longest = 0;
          double best = -1;
          for (int c = 0; c < 3; ++c) {
            const double len = glm::distance(p[tri[(c + 2) % 3]], p[tri[c]]);  // edge opposite tri[(c+1)%3]
            if (len > best) best = len, longest = c;
          }
          const uint32_t a = tri[longest], b = tri[(longest + 1) % 3], c = tri[(longest + 2) % 3];
          const std::vector<uint32_t> across = usersOf(edgeKey(a, c));
          if (across.size() != 2) {
            still.push_back(t);
            continue;
          }
          const uint32_t u = across[0] == t ? across[1] : across[0];
          if (touched[u]) {
            still.push_back(t);
            continue;
          }
          // The neighbour walks a -> c; d is its third corner.
          const glm::uvec3 n = tris[u];
          uint32_t d = 0;
          bool walks_ac = false;
          for (int k = 0; k < 3; ++k) {
            if (n[k] == a && n[(k + 1) % 3] == c) walks_ac = true, d = n[(k + 2) % 3];
          }
          const uint64_t bd = edgeKey(b, d);
          if (!walks_ac || d == b || !usersOf(bd).empty() ||
              std::find(made.begin(), made.end(), bd) != made.end()) {
            still.push_back(t);
            continue;
          }
          tris[t] = glm::uvec3(a, b, d);
          tris[u] = glm::uvec3(b, c, d);
          touched[t] = touched[u] = true;
          made.push_back(bd);
          ++stats.flipped_edges;
          if (isFlat(tris[t])) still.push_back(t);
          if (isFlat(tris[u])) still.push_back(u);
        }
        flat.swap(still);
        std::sort(flat.begin(), flat.end());
        flat.erase(std::unique(flat.begin(), flat.end()), flat.end());
      }
    }
  }

  // 4. Compact: only referenced vertices, in their first order.
  std::vector<uint32_t> remap(mesh.positions.size(), UINT32_MAX);
  std::vector<dvec3> positions, normals;
  for (glm::uvec3& tri : tris)
    for (int c = 0; c < 3; ++c) {
      uint32_t& r = remap[tri[c]];
      if (r == UINT32_MAX) {
        r = uint32_t(positions.size());
        positions.push_back(mesh.positions[tri[c]]);
        normals.push_back(mesh.normals.empty() ? dvec3(0, 0, 1) : mesh.normals[tri[c]]);
      }
      tri[c] = r;
    }
  mesh.positions = std::move(positions);
  mesh.normals = std::move(normals);
  mesh.triangles = std::move(tris);
  mesh.materials = std::move(materials);
  return stats;
}

}  // namespace sdfc
