// Dual contouring on a uniform grid (Ju, Losasso, Schaefer, Warren 2002):
// a vertex per surface cell placed by its QEF, a quad per sign-changing
// edge joining the vertices of the four cells around it.
//
// With MeshOptions::split_patches a cell gets one vertex per surface patch
// instead of one in all: the patches are the marching-cubes components of
// its crossing edges, found by joining crossings along each cube face, as
// in Nielson's Dual Marching Cubes (2004) and level 0 of Schaefer, Ju and
// Warren's Manifold Dual Contouring (2007). A face with four crossings is
// resolved by the sign of the field at its centre, a decision both cells
// sharing the face take alike, so the result is manifold.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <mutex>
#include <numeric>

#include "mesher.h"
#include "parallel.h"
#include "qef.h"

namespace sdfc {
namespace {

using glm::dvec3;
using glm::ivec3;

// Local edge numbering in a cell: axis * 4 + u + 2 v, where u and v are the
// edge's offsets along the next two axes, (axis + 1) % 3 and (axis + 2) % 3.
int localEdge(int axis, const ivec3& offset) {
  return axis * 4 + offset[(axis + 1) % 3] + 2 * offset[(axis + 2) % 3];
}

ivec3 localEdgeOffset(int edge) {
  const int axis = edge / 4;
  ivec3 o(0);
  o[(axis + 1) % 3] = edge & 1;
  o[(axis + 2) % 3] = (edge >> 1) & 1;
  return o;
}

struct Crossing {
  dvec3 point;
  dvec3 normal;
};

struct SurfaceCell {
  uint64_t key = 0;
  uint32_t first_vertex = 0;
  std::array<int8_t, 12> patch{};  // patch of each crossing edge, -1 if none
  uint8_t patch_count = 0;
};

// Union-find over a cell's 12 edges (which crossings form one patch).
struct EdgeUnionFind {
  std::array<int8_t, 12> parent;
  EdgeUnionFind() { std::iota(parent.begin(), parent.end(), int8_t{0}); }
  int find(int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void join(int a, int b) { parent[find(a)] = int8_t(find(b)); }
};

// Where the field crosses zero between a (t = 0) and b (t = 1): Illinois
// false position, bracketed, so it also converges on creases. Many edges at
// once: each edge takes its own steps, but a step of all of them is one
// block evaluation.
struct Search {
  dvec3 a, b;
  double t0 = 0, t1 = 1, f0 = 0, f1 = 0, t = 0.5;
  int side = 0;
  bool done = false, bracketed = true;
};
static_assert(sizeof(dvec3) == 3 * sizeof(double), "points are passed to the evaluator as n x 3 doubles");

void findCrossings(const BlockEvaluator& eval, std::vector<Search>& searches, double voxel,
                   BlockEvaluator::Scratch& scratch, dvec3* out) {
  const size_t n = searches.size();
  std::vector<double> xyz(6 * n), f(2 * n);
  for (size_t i = 0; i < n; ++i) {
    const dvec3& a = searches[i].a;
    const dvec3& b = searches[i].b;
    std::copy(&a.x, &a.x + 3, &xyz[6 * i]);
    std::copy(&b.x, &b.x + 3, &xyz[6 * i + 3]);
  }
  eval.evaluate(xyz.data(), 2 * n, f.data(), nullptr, scratch);
  for (size_t i = 0; i < n; ++i) {
    Search& s = searches[i];
    s.f0 = f[2 * i];
    s.f1 = f[2 * i + 1];
    if ((s.f0 < 0) == (s.f1 < 0)) {  // the sampled signs disagree: give up gently
      s.done = true;
      s.bracketed = false;
      out[i] = 0.5 * (s.a + s.b);
    }
  }
  std::vector<size_t> active;
  for (int iter = 0; iter < 100; ++iter) {
    active.clear();
    xyz.clear();
    for (size_t i = 0; i < n; ++i) {
      Search& s = searches[i];
      if (s.done) continue;
      s.t = (s.t0 * s.f1 - s.t1 * s.f0) / (s.f1 - s.f0);
      if (!(s.t > s.t0 && s.t < s.t1)) s.t = 0.5 * (s.t0 + s.t1);
      const dvec3 p = s.a + s.t * (s.b - s.a);
      xyz.insert(xyz.end(), {p.x, p.y, p.z});
      active.push_back(i);
    }
    if (active.empty()) break;
    eval.evaluate(xyz.data(), active.size(), f.data(), nullptr, scratch);
    for (size_t k = 0; k < active.size(); ++k) {
      Search& s = searches[active[k]];
      const double fk = f[k];
      if (fk == 0 || std::fabs(fk) < 1e-13 * voxel || s.t1 - s.t0 < 1e-13) {
        s.done = true;
      } else if ((fk < 0) == (s.f0 < 0)) {
        s.t0 = s.t, s.f0 = fk;
        if (s.side == -1) s.f1 *= 0.5;
        s.side = -1;
      } else {
        s.t1 = s.t, s.f1 = fk;
        if (s.side == 1) s.f0 *= 0.5;
        s.side = 1;
      }
    }
  }
  for (size_t i = 0; i < n; ++i) {
    const Search& s = searches[i];
    if (s.bracketed) out[i] = s.a + s.t * (s.b - s.a);
  }
}

// Newton steps onto the surface, staying in the cell: vertices on creases
// already have f = 0 and do not move; the rest lose the QEF's curvature
// error (~voxel^2 / radius) and the clamping error. Each vertex takes its
// own steps; a step of all of them is one block evaluation.
struct Projection {
  dvec3 v, lo, hi;
  dvec3* out;
  bool done = false;
};

void projectOntoSurface(const BlockEvaluator& eval, std::vector<Projection>& vertices, int steps, double voxel,
                        double h, BlockEvaluator::Scratch& scratch) {
  std::vector<size_t> active, moving;
  std::vector<double> xyz, f, g;
  for (int iter = 0; iter < steps; ++iter) {
    active.clear();
    xyz.clear();
    for (size_t i = 0; i < vertices.size(); ++i) {
      if (vertices[i].done) continue;
      active.push_back(i);
      xyz.insert(xyz.end(), {vertices[i].v.x, vertices[i].v.y, vertices[i].v.z});
    }
    if (active.empty()) break;
    f.resize(active.size());
    eval.evaluate(xyz.data(), active.size(), f.data(), nullptr, scratch);
    moving.clear();
    size_t m = 0;
    for (size_t k = 0; k < active.size(); ++k) {
      if (std::fabs(f[k]) <= 1e-12 * voxel) {
        vertices[active[k]].done = true;
        continue;
      }
      moving.push_back(k);
      std::copy(&xyz[3 * k], &xyz[3 * k] + 3, &xyz[3 * m++]);
    }
    g.resize(3 * m);
    eval.gradient(xyz.data(), m, g.data(), scratch, h);
    for (size_t j = 0; j < m; ++j) {
      Projection& p = vertices[active[moving[j]]];
      const dvec3 gj(g[3 * j], g[3 * j + 1], g[3 * j + 2]);
      const double g2 = glm::dot(gj, gj);
      if (!(g2 > 1e-12)) {
        p.done = true;
        continue;
      }
      p.v = glm::clamp(p.v - gj * (f[moving[j]] / g2), p.lo, p.hi);
    }
  }
  for (const Projection& p : vertices) *p.out = p.v;
}

}  // namespace

TriangleMesh dualContour(const BlockEvaluator& block, const SignGrid& grid, const MeshOptions& options,
                         ContourStats* stats) {
  const auto start = std::chrono::steady_clock::now();
  const Evaluator& eval = block.pointwise();
  std::vector<BlockEvaluator::Scratch> scratch(workerCount(options.threads));
  const GridPlan& plan = grid.plan;
  const ivec3 s = plan.samples();
  const ivec3 cells = plan.cells;
  const int threads = options.threads;
  auto sampleOf = [&](uint64_t index) {
    const uint64_t sx = uint64_t(s.x), sy = uint64_t(s.y);
    return ivec3(int(index % sx), int(index / sx % sy), int(index / (sx * sy)));
  };
  auto cellKey = [&](const ivec3& c) {
    return uint64_t(c.x) + uint64_t(cells.x) * (uint64_t(c.y) + uint64_t(cells.y) * uint64_t(c.z));
  };
  auto inside = [&](const ivec3& p) { return grid.inside[grid.index(p.x, p.y, p.z)] != 0; };
  std::mutex progress_mutex;
  auto report = [&](const char* stage, size_t done, size_t total) {
    if (!options.progress) return;
    std::lock_guard<std::mutex> lock(progress_mutex);
    options.progress(stage, double(std::min(done, total)) / double(std::max<size_t>(total, 1)));
  };
  auto stopped = [&] { return options.interrupt && options.interrupt->load(); };

  // 1. Sign-changing edges, key = sample index * 3 + axis. Slabs are scanned
  // in order, so the concatenation is sorted for binary search.
  std::vector<std::vector<uint64_t>> slab_edges(size_t(s.z));
  parallelFor(size_t(s.z), 4, threads, [&](size_t begin, size_t end, int) {
    for (size_t k = begin; k < end; ++k)
      for (int j = 0; j < s.y; ++j)
        for (int i = 0; i < s.x; ++i) {
          const ivec3 p(i, j, int(k));
          const bool in = inside(p);
          for (int axis = 0; axis < 3; ++axis) {
            ivec3 q = p;
            ++q[axis];
            if (q[axis] < s[axis] && inside(q) != in)
              slab_edges[k].push_back(grid.index(i, j, int(k)) * 3 + uint64_t(axis));
          }
        }
  });
  std::vector<uint64_t> edges;
  for (auto& e : slab_edges) edges.insert(edges.end(), e.begin(), e.end());
  slab_edges.clear();

  // 2. Hermite data: exact crossing by root finding, normal from the gradient.
  std::vector<Crossing> crossings(edges.size());
  const double h = 1e-5 * plan.voxel;
  std::atomic<size_t> edges_done{0};
  parallelFor(edges.size(), 256, threads, [&](size_t begin, size_t end, int worker) {
    if (stopped()) return;
    report("edges", edges_done += end - begin, edges.size());
    std::vector<Search> searches(end - begin);
    for (size_t e = begin; e < end; ++e) {
      const int axis = int(edges[e] % 3);
      const ivec3 p = sampleOf(edges[e] / 3);
      ivec3 q = p;
      ++q[axis];
      searches[e - begin].a = plan.point(p.x, p.y, p.z);
      searches[e - begin].b = plan.point(q.x, q.y, q.z);
    }
    std::vector<dvec3> points(end - begin);
    findCrossings(block, searches, plan.voxel, scratch[worker], points.data());
    std::vector<dvec3> gradients(end - begin);
    block.gradient(&points[0].x, points.size(), &gradients[0].x, scratch[worker], h);
    for (size_t e = begin; e < end; ++e) {
      const int axis = int(edges[e] % 3);
      const ivec3 p = sampleOf(edges[e] / 3);
      Crossing& c = crossings[e];
      c.point = points[e - begin];
      const dvec3 g = gradients[e - begin];
      const double len = glm::length(g);
      dvec3 fallback(0);
      fallback[axis] = inside(p) ? 1 : -1;  // outward along the edge
      c.normal = len > 1e-12 ? g / len : fallback;
    }
  });
  auto findEdge = [&](uint64_t key) -> int64_t {
    auto it = std::lower_bound(edges.begin(), edges.end(), key);
    return it != edges.end() && *it == key ? int64_t(it - edges.begin()) : -1;
  };

  // 3. Surface cells: every cell touching a crossing edge.
  std::vector<uint64_t> cell_keys;
  cell_keys.reserve(edges.size() * 2);
  for (uint64_t key : edges) {
    const int axis = int(key % 3);
    const ivec3 p = sampleOf(key / 3);
    const int b = (axis + 1) % 3, c = (axis + 2) % 3;
    for (int db = 0; db < 2; ++db)
      for (int dc = 0; dc < 2; ++dc) {
        ivec3 cell = p;
        cell[b] += db - 1;
        cell[c] += dc - 1;
        if (glm::all(glm::greaterThanEqual(cell, ivec3(0))) && glm::all(glm::lessThan(cell, cells)))
          cell_keys.push_back(cellKey(cell));
      }
  }
  std::sort(cell_keys.begin(), cell_keys.end());
  cell_keys.erase(std::unique(cell_keys.begin(), cell_keys.end()), cell_keys.end());
  auto cellOf = [&](uint64_t key) {
    const uint64_t cx = uint64_t(cells.x), cy = uint64_t(cells.y);
    return ivec3(int(key % cx), int(key / cx % cy), int(key / (cx * cy)));
  };

  // 4. Patches per cell: crossings joined along each face. A face with four
  // crossings pairs them by the sign at its centre (both cells alike). Where
  // that leaves one patch of each cell meeting the other across the face
  // twice (a tunnel through the face: both cells' single patch holds both
  // segments), the dual edge between their vertices would border four
  // triangles; the face then takes the other pairing, which splits both
  // patches in two (the castle at 160 had two such edges).
  struct CellCrossings {
    bool corner[8];
    int64_t crossing_of[12];
  };
  auto crossingsOf = [&](const ivec3& cell) {
    CellCrossings cc;
    for (int n = 0; n < 8; ++n) cc.corner[n] = inside(cell + ivec3(n & 1, (n >> 1) & 1, (n >> 2) & 1));
    for (int e = 0; e < 12; ++e) {
      const int axis = e / 4;
      const ivec3 o = localEdgeOffset(e);
      ivec3 o2 = o;
      o2[axis] = 1;
      cc.crossing_of[e] = -1;
      if (cc.corner[o.x + 2 * o.y + 4 * o.z] != cc.corner[o2.x + 2 * o2.y + 4 * o2.z]) {
        const ivec3 p = cell + o;
        cc.crossing_of[e] = findEdge(grid.index(p.x, p.y, p.z) * 3 + uint64_t(axis));
      }
    }
    return cc;
  };
  // Joins the cell's crossings into patches; faces in `flip` (bit a * 2 + side)
  // take the pairing the centre does not. Returns the ambiguous faces whose
  // two segments ended in one patch.
  auto joinPatches = [&](const ivec3& cell, const CellCrossings& cc, unsigned flip, EdgeUnionFind& uf) {
    unsigned tunnels = 0;
    int ambiguous[6][2];  // fe[0], fe[2] of each face with four crossings
    for (auto& f : ambiguous) f[0] = f[1] = -1;
    auto cornerAt = [&](const ivec3& o) { return cc.corner[o.x + 2 * o.y + 4 * o.z]; };
    for (int a = 0; a < 3; ++a) {
      const int b = (a + 1) % 3, c = (a + 2) % 3;
      for (int side = 0; side < 2; ++side) {
        // Face corners q0..q3 counter-clockwise in (b, c); edges e01, e12, e23, e30.
        ivec3 q[4];
        for (int n = 0; n < 4; ++n) {
          q[n] = ivec3(0);
          q[n][a] = side;
        }
        q[1][b] = 1, q[2][b] = 1, q[2][c] = 1, q[3][c] = 1;
        const int fe[4] = {localEdge(b, q[0]), localEdge(c, q[1]), localEdge(b, q[3]), localEdge(c, q[0])};
        int present[4], n_present = 0;
        for (int n = 0; n < 4; ++n)
          if (cc.crossing_of[fe[n]] >= 0) present[n_present++] = fe[n];
        if (n_present == 2) {
          uf.join(present[0], present[1]);
        } else if (n_present == 4) {
          // Ambiguous face: q0, q2 share a sign; the centre says whether they connect.
          ivec3 base = cell;
          base[a] += side;
          dvec3 centre = plan.point(base.x, base.y, base.z);
          centre[b] += 0.5 * plan.voxel;
          centre[c] += 0.5 * plan.voxel;
          const bool centre_in = eval.distance(centre) < 0;
          const bool flipped = (flip >> (a * 2 + side)) & 1;
          ambiguous[a * 2 + side][0] = fe[0];
          ambiguous[a * 2 + side][1] = fe[2];
          if ((centre_in == cornerAt(q[0])) != flipped) {  // q0-q2 joined: cut off q1 and q3
            uf.join(fe[0], fe[1]);
            uf.join(fe[2], fe[3]);
          } else {  // cut off q0 and q2
            uf.join(fe[3], fe[0]);
            uf.join(fe[1], fe[2]);
          }
        }
      }
    }
    // fe[0] and fe[2] are in different segments under either pairing.
    for (int f = 0; f < 6; ++f)
      if (ambiguous[f][0] >= 0 && uf.find(ambiguous[f][0]) == uf.find(ambiguous[f][1])) tunnels |= 1u << f;
    return tunnels;
  };
  std::vector<uint8_t> tunnels(cell_keys.size(), 0);
  if (options.split_patches) {
    parallelFor(cell_keys.size(), 256, threads, [&](size_t begin, size_t end, int) {
      for (size_t ci = begin; ci < end; ++ci) {
        const ivec3 cell = cellOf(cell_keys[ci]);
        EdgeUnionFind uf;
        tunnels[ci] = uint8_t(joinPatches(cell, crossingsOf(cell), 0, uf));
      }
    });
  }
  auto tunnelsOf = [&](const ivec3& cell) -> unsigned {
    if (glm::any(glm::lessThan(cell, ivec3(0))) || glm::any(glm::greaterThanEqual(cell, cells))) return 0;
    auto it = std::lower_bound(cell_keys.begin(), cell_keys.end(), cellKey(cell));
    return it != cell_keys.end() && *it == cellKey(cell) ? tunnels[size_t(it - cell_keys.begin())] : 0;
  };

  // 5. QEF vertices per patch (up to four patches a cell).
  std::vector<SurfaceCell> surface(cell_keys.size());
  std::vector<std::array<dvec3, 4>> cell_vertices(cell_keys.size());
  std::atomic<size_t> clamped{0};
  std::atomic<size_t> cells_done{0};
  std::atomic<size_t> flipped_faces{0};
  parallelFor(cell_keys.size(), 256, threads, [&](size_t begin, size_t end, int worker) {
    if (stopped()) return;
    std::vector<Projection> projections;
    for (size_t ci = begin; ci < end; ++ci) {
      SurfaceCell& sc = surface[ci];
      sc.key = cell_keys[ci];
      const ivec3 cell = cellOf(sc.key);
      const CellCrossings cc = crossingsOf(cell);
      const int64_t* crossing_of = cc.crossing_of;
      unsigned flip = 0;
      for (int f = 0; f < 6 && tunnels[ci]; ++f) {
        if (!((tunnels[ci] >> f) & 1)) continue;
        ivec3 other = cell;
        other[f / 2] += (f & 1) ? 1 : -1;
        if ((tunnelsOf(other) >> (f ^ 1)) & 1) flip |= 1u << f;
      }
      if (flip) ++flipped_faces;
      EdgeUnionFind uf;
      if (options.split_patches) joinPatches(cell, cc, flip, uf);
      sc.patch.fill(-1);
      int root_patch[12];
      std::fill(std::begin(root_patch), std::end(root_patch), -1);
      Qef qefs[4];
      for (int e = 0; e < 12; ++e) {
        if (crossing_of[e] < 0) continue;
        const int root = options.split_patches ? uf.find(e) : 0;
        if (root_patch[root] < 0) root_patch[root] = sc.patch_count++;
        sc.patch[e] = int8_t(root_patch[root]);
        const Crossing& x = crossings[size_t(crossing_of[e])];
        qefs[sc.patch[e]].add(x.point, x.normal);
      }
      const dvec3 lo = plan.point(cell.x, cell.y, cell.z), hi = lo + plan.voxel;
      for (int p = 0; p < sc.patch_count; ++p) {
        const dvec3 solved = qefs[p].solve();
        const dvec3 v = glm::clamp(solved, lo, hi);
        if (v != solved) ++clamped;
        projections.push_back({v, lo, hi, &cell_vertices[ci][p]});
      }
    }
    projectOntoSurface(block, projections, options.project_steps, plan.voxel, h, scratch[worker]);
    report("contouring", cells_done += end - begin, surface.size());
  });

  TriangleMesh mesh;
  if (stopped()) {
    if (stats) stats->interrupted = true;
    return mesh;
  }
  size_t split = 0;
  for (size_t ci = 0; ci < surface.size(); ++ci) {
    surface[ci].first_vertex = uint32_t(mesh.positions.size());
    for (int p = 0; p < surface[ci].patch_count; ++p) mesh.positions.push_back(cell_vertices[ci][p]);
    if (surface[ci].patch_count > 1) ++split;
  }
  cell_vertices.clear();

  // 6. A quad per crossing edge, wound so its normal points from inside to
  // outside, split along the shorter diagonal.
  auto vertexOf = [&](const ivec3& cell, int local_edge) -> int64_t {
    const uint64_t key = cellKey(cell);
    auto it = std::lower_bound(cell_keys.begin(), cell_keys.end(), key);
    const SurfaceCell& sc = surface[size_t(it - cell_keys.begin())];
    return int64_t(sc.first_vertex) + sc.patch[local_edge];
  };
  mesh.triangles.reserve(edges.size() * 2);
  for (uint64_t key : edges) {
    const int axis = int(key % 3);
    const ivec3 p = sampleOf(key / 3);
    const int b = (axis + 1) % 3, c = (axis + 2) % 3;
    static constexpr int kCycle[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};  // (db, dc), ccw about +axis
    uint32_t quad[4];
    bool complete = true;
    for (int n = 0; n < 4 && complete; ++n) {
      ivec3 cell = p;
      cell[b] += kCycle[n][0] - 1;
      cell[c] += kCycle[n][1] - 1;
      if (glm::any(glm::lessThan(cell, ivec3(0))) || glm::any(glm::greaterThanEqual(cell, cells))) {
        complete = false;  // the region's border cuts the surface: leave it open
        break;
      }
      ivec3 offset(0);
      offset[b] = 1 - kCycle[n][0];
      offset[c] = 1 - kCycle[n][1];
      quad[n] = uint32_t(vertexOf(cell, localEdge(axis, offset)));
    }
    if (!complete) continue;
    if (!inside(p)) std::swap(quad[1], quad[3]);
    const dvec3* v = mesh.positions.data();
    if (glm::distance(v[quad[0]], v[quad[2]]) <= glm::distance(v[quad[1]], v[quad[3]])) {
      mesh.triangles.emplace_back(quad[0], quad[1], quad[2]);
      mesh.triangles.emplace_back(quad[0], quad[2], quad[3]);
    } else {
      mesh.triangles.emplace_back(quad[0], quad[1], quad[3]);
      mesh.triangles.emplace_back(quad[1], quad[2], quad[3]);
    }
  }

  // 7. Vertex normals and triangle materials from the evaluator.
  mesh.normals.resize(mesh.positions.size());
  parallelFor(mesh.positions.size(), 512, threads, [&](size_t begin, size_t end, int worker) {
    std::vector<dvec3> gradients(end - begin);
    block.gradient(&mesh.positions[begin].x, end - begin, &gradients[0].x, scratch[worker], h);
    for (size_t i = begin; i < end; ++i) {
      const dvec3 g = gradients[i - begin];
      const double len = glm::length(g);
      mesh.normals[i] = len > 1e-12 ? g / len : dvec3(0, 0, 1);
    }
  });
  mesh.materials.resize(mesh.triangles.size());
  parallelFor(mesh.triangles.size(), 512, threads, [&](size_t begin, size_t end, int worker) {
    std::vector<dvec3> centroids(end - begin);
    for (size_t t = begin; t < end; ++t) {
      const glm::uvec3 tri = mesh.triangles[t];
      centroids[t - begin] = (mesh.positions[tri.x] + mesh.positions[tri.y] + mesh.positions[tri.z]) / 3.0;
    }
    block.evaluate(&centroids[0].x, end - begin, nullptr, &mesh.materials[begin], scratch[worker]);
  });

  if (stats) {
    stats->crossing_edges = edges.size();
    stats->surface_cells = surface.size();
    stats->split_cells = split;
    stats->clamped_vertices = clamped;
    stats->tunnel_faces = flipped_faces;
    stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  return mesh;
}

}  // namespace sdfc
