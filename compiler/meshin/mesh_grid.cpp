#include "meshin/mesh_grid.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <numeric>
#include <thread>

#include "meshin/mesh_distance.h"

namespace sdfc {
namespace {

// Union-find over the grid's corners, by index.
struct Components {
  std::vector<std::uint32_t> parent;
  explicit Components(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  std::uint32_t find(std::uint32_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  }
  void join(std::uint32_t a, std::uint32_t b) {
    a = find(a), b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

// Runs body(z) for every z slab on the machine's cores.
template <class F>
void forSlabs(int slabs, F body) {
  const int threads = std::clamp(int(std::thread::hardware_concurrency()), 1, 16);
  std::vector<std::thread> pool;
  std::atomic<int> next{0};
  for (int t = 0; t < threads; ++t)
    pool.emplace_back([&] {
      for (int z; (z = next++) < slabs;) body(z);
    });
  for (std::thread& t : pool) t.join();
}

}  // namespace

MeshGridLayout meshGridLayout(const Aabb& box, int cells) {
  MeshGridLayout l;
  l.mesh_box = box;
  const glm::dvec3 extent = box.hi - box.lo;
  const double longest = std::max({extent.x, extent.y, extent.z, 1e-30});
  l.cell = longest / cells;
  for (int a = 0; a < 3; ++a) {
    const int inner = std::max(1, int(std::ceil(extent[a] / l.cell - 1e-9)));
    l.dims[a] = inner + 2 * kMeshGridPad + 1;
    // Centred on the box, the pad the same both sides.
    l.lo[a] = box.center()[a] - 0.5 * (l.dims[a] - 1) * l.cell;
  }
  l.band = kMeshGridBand * l.cell;
  return l;
}

MeshGrid buildMeshGrid(const MeshDistance& mesh, const MeshGridLayout& l) {
  const auto start = std::chrono::steady_clock::now();
  MeshGrid g;
  const glm::ivec3 n = l.dims;
  const size_t count = l.corners();
  auto at = [&](int x, int y, int z) { return (size_t(z) * n.y + y) * n.x + x; };
  auto corner = [&](int x, int y, int z) { return l.lo + glm::dvec3(x, y, z) * l.cell; };
  // Unsigned distances, capped at the band. Corners go in bricks of
  // kBrick^3: one query at a brick's centre, capped at the band plus its half
  // diagonal, settles a brick with no triangle that near (most of them), each
  // corner then the band as its own query would give.
  constexpr int kBrick = 4;
  const double half_diagonal = 0.5 * std::sqrt(3.0) * (kBrick - 1) * l.cell;
  std::vector<double> d(count);
  forSlabs((n.z + kBrick - 1) / kBrick, [&](int bz) {
    for (int by = 0; by < n.y; by += kBrick)
      for (int bx = 0; bx < n.x; bx += kBrick) {
        const int z0 = bz * kBrick, z1 = std::min(z0 + kBrick, n.z);
        const int y1 = std::min(by + kBrick, n.y), x1 = std::min(bx + kBrick, n.x);
        const glm::dvec3 centre = 0.5 * (corner(bx, by, z0) + corner(x1 - 1, y1 - 1, z1 - 1));
        const bool empty = mesh.unsignedDistance(centre, l.band + half_diagonal) >= l.band + half_diagonal;
        for (int z = z0; z < z1; ++z)
          for (int y = by; y < y1; ++y)
            for (int x = bx; x < x1; ++x)
              d[at(x, y, z)] = empty ? l.band : mesh.unsignedDistance(corner(x, y, z), l.band);
      }
  });
  // Two neighbours whose distances sum to more than the edge between them
  // have no surface on that edge: they share a side. Each connected region
  // takes one sign, the majority of the winding numbers of a few of its
  // corners (its farthest from the surface first).
  Components c(count);
  for (int z = 0; z < n.z; ++z)
    for (int y = 0; y < n.y; ++y)
      for (int x = 0; x < n.x; ++x) {
        const size_t i = at(x, y, z);
        if (x + 1 < n.x && d[i] + d[i + 1] > l.cell) c.join(i, i + 1);
        if (y + 1 < n.y && d[i] + d[at(x, y + 1, z)] > l.cell) c.join(i, at(x, y + 1, z));
        if (z + 1 < n.z && d[i] + d[at(x, y, z + 1)] > l.cell) c.join(i, at(x, y, z + 1));
      }
  constexpr int kVotes = 5;
  struct Region {
    std::vector<std::uint32_t> samples;
    int inside = 0, outside = 0;
  };
  std::vector<std::int32_t> region_of(count, -1);
  std::vector<Region> regions;
  for (size_t i = 0; i < count; ++i) {
    const std::uint32_t root = c.find(static_cast<std::uint32_t>(i));
    if (region_of[root] < 0) {
      region_of[root] = static_cast<std::int32_t>(regions.size());
      regions.push_back({});
    }
    Region& r = regions[region_of[root]];
    // Samples spread through the region: its first corners, then every so often.
    if (r.samples.size() < kVotes && (r.samples.empty() || d[i] >= d[r.samples.back()])) r.samples.push_back(i);
  }
  std::vector<std::uint32_t> queries;
  for (const Region& r : regions) queries.insert(queries.end(), r.samples.begin(), r.samples.end());
  std::vector<char> inside(queries.size());
  const int chunks = static_cast<int>(std::min<size_t>(queries.size(), 256));
  forSlabs(chunks, [&](int k) {
    for (size_t q = k; q < queries.size(); q += chunks) {
      const size_t i = queries[q];
      const int x = int(i % n.x), y = int(i / n.x % n.y), z = int(i / (size_t(n.x) * n.y));
      inside[q] = mesh.winding(corner(x, y, z)) > 0.5;
    }
  });
  size_t q = 0;
  for (Region& r : regions)
    for (size_t s = 0; s < r.samples.size(); ++s, ++q) (inside[q] ? r.inside : r.outside)++;
  g.winding_queries = queries.size();
  g.values.resize(count);
  for (size_t i = 0; i < count; ++i) {
    const Region& r = regions[region_of[c.find(static_cast<std::uint32_t>(i))]];
    g.values[i] = static_cast<float>(r.inside > r.outside ? -d[i] : d[i]);
  }
  g.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return g;
}

size_t appendMeshGridData(const MeshGridLayout& l, const MeshGrid& g, std::vector<float>& data) {
  const size_t header = data.size() / 4;
  const float v[16] = {float(l.lo.x),         float(l.lo.y),         float(l.lo.z),         float(l.cell),
                       float(l.dims.x),       float(l.dims.y),       float(l.dims.z),       0,
                       float(l.mesh_box.lo.x), float(l.mesh_box.lo.y), float(l.mesh_box.lo.z), 0,
                       float(l.mesh_box.hi.x), float(l.mesh_box.hi.y), float(l.mesh_box.hi.z), 0};
  data.insert(data.end(), v, v + 16);
  data.insert(data.end(), g.values.begin(), g.values.end());
  while (data.size() % 4 != 0) data.push_back(0);
  return header;
}

const char* meshGridGlsl() {
  return R"(// A mesh's sampled signed distance (meshin/mesh_grid.cpp): trilinear between
// the grid's corners, within (sqrt 3 / 2) * cell of the exact distance; outside
// the grid, the distance to the mesh's box (a lower bound).
float sdMeshGridValue(int values, int i) { return sd_data[values + (i >> 2)][i & 3]; }
float sdMeshGrid(vec3 p, int base) {
  vec4 h0 = sd_data[base], h1 = sd_data[base + 1];
  vec3 box_lo = sd_data[base + 2].xyz, box_hi = sd_data[base + 3].xyz;
  ivec3 dims = ivec3(h1.xyz);
  vec3 hi = h0.xyz + vec3(dims - 1) * h0.w;
  vec3 q = clamp(p, h0.xyz, hi);
  if (q != p) return length(max(max(box_lo - p, p - box_hi), 0.0));
  vec3 g = (q - h0.xyz) / h0.w;
  ivec3 c = clamp(ivec3(floor(g)), ivec3(0), dims - 2);
  vec3 t = clamp(g - vec3(c), 0.0, 1.0);
  int values = base + 4;
  int i = c.x + dims.x * (c.y + dims.y * c.z);
  int sy = dims.x, sz = dims.x * dims.y;
  float x00 = mix(sdMeshGridValue(values, i), sdMeshGridValue(values, i + 1), t.x);
  float x10 = mix(sdMeshGridValue(values, i + sy), sdMeshGridValue(values, i + sy + 1), t.x);
  float x01 = mix(sdMeshGridValue(values, i + sz), sdMeshGridValue(values, i + sz + 1), t.x);
  float x11 = mix(sdMeshGridValue(values, i + sy + sz), sdMeshGridValue(values, i + sy + sz + 1), t.x);
  return mix(mix(x00, x10, t.y), mix(x01, x11, t.y), t.z);
}
)";
}

}  // namespace sdfc
