#include "meshin/mesh_distance.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace sdfc {
namespace {

using glm::dvec3;

double boxDistance2(const Aabb& b, const dvec3& p) {
  const dvec3 d = glm::max(glm::max(b.lo - p, p - b.hi), dvec3(0));
  return glm::dot(d, d);
}

// The squared distance from p to triangle abc: the nearest of the face's
// interior, its edges and its vertices by the region p's projection falls in
// (Ericson, Real-Time Collision Detection, 5.1.5).
double triangleDistance2(const dvec3& p, const dvec3& a, const dvec3& b, const dvec3& c) {
  const dvec3 ab = b - a, ac = c - a, ap = p - a;
  auto len2 = [](const dvec3& v) { return glm::dot(v, v); };
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return len2(ap);
  const dvec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return len2(bp);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return len2(ap - ab * (d1 / (d1 - d3)));
  const dvec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return len2(cp);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return len2(ap - ac * (d2 / (d2 - d6)));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
    return len2(bp - (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))));
  const double denom = 1 / (va + vb + vc);
  return len2(ap - ab * (vb * denom) - ac * (vc * denom));
}

}  // namespace

double pointTriangleDistance(const dvec3& p, const dvec3& a, const dvec3& b, const dvec3& c) {
  return std::sqrt(triangleDistance2(p, a, b, c));
}

double triangleSolidAngle(const dvec3& p, const dvec3& a0, const dvec3& b0, const dvec3& c0) {
  const dvec3 a = a0 - p, b = b0 - p, c = c0 - p;
  const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
  const double num = glm::dot(a, glm::cross(b, c));
  const double den = la * lb * lc + glm::dot(a, b) * lc + glm::dot(a, c) * lb + glm::dot(b, c) * la;
  return 2 * std::atan2(num, den);
}

namespace {

struct TriangleBvhBuilder {
  const std::vector<dvec3>& centroid;
  std::vector<std::uint32_t>& order;
  std::vector<MeshBvhNode>& nodes;
  int depth = 0;

  // Splits at the median centroid along the longest axis of the centroids' box.
  void build(std::uint32_t index, std::uint32_t begin, std::uint32_t end, int level) {
    depth = std::max(depth, level);
    if (end - begin <= kMeshLeafSize) {
      nodes[index].first = begin;
      nodes[index].count = end - begin;
      return;
    }
    Aabb c;
    for (std::uint32_t k = begin; k < end; ++k) c = c.unite({centroid[order[k]], centroid[order[k]]});
    const dvec3 extent = c.hi - c.lo;
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
    const std::uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end,
                     [&](std::uint32_t a, std::uint32_t b) { return centroid[a][axis] < centroid[b][axis]; });
    const std::uint32_t left = static_cast<std::uint32_t>(nodes.size());
    nodes.push_back({});
    build(left, begin, mid, level + 1);
    const std::uint32_t right = static_cast<std::uint32_t>(nodes.size());
    nodes.push_back({});
    build(right, mid, end, level + 1);
    nodes[index].first = right;
    nodes[index].count = 0;
  }
};

}  // namespace

MeshDistance::MeshDistance(const InputMesh& mesh) {
  const size_t n = mesh.triangles.size();
  std::vector<dvec3> centroid(n);
  for (size_t t = 0; t < n; ++t) {
    const glm::uvec3& i = mesh.triangles[t];
    centroid[t] = (mesh.vertices[i[0]] + mesh.vertices[i[1]] + mesh.vertices[i[2]]) / 3.0;
  }
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  nodes_.reserve(2 * (n / kMeshLeafSize + 1));
  nodes_.push_back({});
  TriangleBvhBuilder b{centroid, order, nodes_};
  if (n > 0) b.build(0, 0, static_cast<std::uint32_t>(n), 1);
  depth_ = b.depth;
  corners_.resize(3 * n);
  for (size_t t = 0; t < n; ++t)
    for (int k = 0; k < 3; ++k) corners_[3 * t + k] = mesh.vertices[mesh.triangles[order[t]][k]];
  // Boxes and dipoles bottom up (children have larger indices than parents);
  // centres weighted by the triangles' areas.
  std::vector<double> weight(nodes_.size(), 0);
  std::vector<dvec3> moment(nodes_.size(), dvec3(0));
  for (size_t i = nodes_.size(); i-- > 0;) {
    MeshBvhNode& node = nodes_[i];
    if (node.count > 0) {
      Aabb box;
      for (std::uint32_t t = node.first; t < node.first + node.count; ++t) {
        const dvec3 &a = corners_[3 * t], &b2 = corners_[3 * t + 1], &c = corners_[3 * t + 2];
        box = box.unite({glm::min(a, glm::min(b2, c)), glm::max(a, glm::max(b2, c))});
        const dvec3 v = 0.5 * glm::cross(b2 - a, c - a);
        const double s = glm::length(v);
        node.area += v;
        weight[i] += s;
        moment[i] += s * (a + b2 + c) / 3.0;
      }
      node.box = box;
    } else {
      const std::uint32_t l = static_cast<std::uint32_t>(i + 1), r = node.first;
      node.box = nodes_[l].box.unite(nodes_[r].box);
      node.area = nodes_[l].area + nodes_[r].area;
      weight[i] = weight[l] + weight[r];
      moment[i] = moment[l] + moment[r];
    }
    node.centre = weight[i] > 0 ? moment[i] / weight[i] : node.box.center();
    // Every corner lies in the box: its farthest corner from the centre bounds them.
    node.radius = glm::length(glm::max(glm::abs(node.box.lo - node.centre), glm::abs(node.box.hi - node.centre)));
  }
}

double MeshDistance::unsignedDistance(const dvec3& p, double cap) const {
  double best2 = cap * cap;
  if (corners_.empty()) return cap;
  struct Entry {
    std::uint32_t node;
    double d2;
  };
  Entry stack[128];
  int top = 0;
  stack[top++] = {0, boxDistance2(nodes_[0].box, p)};
  while (top > 0) {
    const Entry e = stack[--top];
    if (e.d2 >= best2) continue;
    const MeshBvhNode& node = nodes_[e.node];
    if (node.count == 0) {
      const std::uint32_t l = e.node + 1, r = node.first;
      const double dl = boxDistance2(nodes_[l].box, p), dr = boxDistance2(nodes_[r].box, p);
      // The nearer child on top: visited first, it shrinks best2 for the other.
      if (dl < dr) {
        if (dr < best2) stack[top++] = {r, dr};
        if (dl < best2) stack[top++] = {l, dl};
      } else {
        if (dl < best2) stack[top++] = {l, dl};
        if (dr < best2) stack[top++] = {r, dr};
      }
      continue;
    }
    for (std::uint32_t t = node.first; t < node.first + node.count; ++t)
      best2 = std::min(best2, triangleDistance2(p, corners_[3 * t], corners_[3 * t + 1], corners_[3 * t + 2]));
  }
  return std::sqrt(best2);
}

double MeshDistance::winding(const dvec3& p) const {
  if (corners_.empty()) return 0;
  constexpr double kFourPi = 4 * 3.14159265358979323846;
  double sum = 0;
  std::uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const MeshBvhNode& node = nodes_[stack[--top]];
    const dvec3 r = node.centre - p;
    const double d2 = glm::dot(r, r);
    if (node.count == 0 && d2 > kWindingFarFactor * kWindingFarFactor * node.radius * node.radius) {
      // The dipole's solid angle: area . r / |r|^3 (first order in radius / |r|).
      sum += glm::dot(node.area, r) / (d2 * std::sqrt(d2));
      continue;
    }
    if (node.count == 0) {
      stack[top++] = node.first;
      stack[top++] = static_cast<std::uint32_t>(&node - nodes_.data()) + 1;
      continue;
    }
    for (std::uint32_t t = node.first; t < node.first + node.count; ++t)
      sum += triangleSolidAngle(p, corners_[3 * t], corners_[3 * t + 1], corners_[3 * t + 2]);
  }
  return sum / kFourPi;
}

double MeshDistance::signedDistance(const dvec3& p) const {
  const double d = unsignedDistance(p);
  return winding(p) > 0.5 ? -d : d;
}

}  // namespace sdfc
