// Which bounding-volume checks pay on a device that runs lanes in lockstep
// (issue 46: "--bounds as a user-facing switch should no longer matter").
//
// A union may guard a child with the distance to the child's box: when every
// lane of a group is farther from the box than the union's distance so far,
// the group skips the child (the emitter's subgroupAny). On lavapipe the check
// itself is not free, and where boxes overlap (the castle) it rarely skips:
// all checks cost the castle 21%, yet a chess set of 32 separated pieces runs
// 2.7x faster with them (bench/results/bounds_plan.md). So the compiler
// measures, on the CPU, what each check would save on this scene, seen from
// this camera:
//  - it marches groups of 8 neighbouring pixels' rays in lockstep (4 x 2, as
//    lavapipe's 256-bit lanes shade them) with the float64 evaluator, and from
//    each hit a shadow ray and a diffuse bounce;
//  - at every step it evaluates the unions the way the kernel would with every
//    candidate checked, counting per child the steps its group reached it and
//    the steps the group had to evaluate it;
//  - a child is checked where (share of steps skipped) x (its cost) exceeds a
//    check's cost (kCheckCost), which is calibrated on measured renders.
// The plan depends only on the scene and the image height: deterministic, so
// farm shards compile the same kernel.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "eval/evaluator.h"
#include "eval/noise.h"
#include "passes.h"

namespace sdfc {
namespace {

using glm::dvec3;
constexpr int kLanes = 8;
// What one check costs, in the analysis's units (a primitive is 1). The box
// distance and the vote are about 1.5, but a check also makes the steps near
// the child shorter (the box distance stands in for it: the castle's primary
// steps +10%, the chess set's +19%) and splits the code the driver schedules.
// Measured in CPU time at 320x180, 16 spp (bench/results/bounds_plan.md): at
// 3 the castle keeps 4 checks and runs 0.94x, at 5 it keeps 3 (0.98x), at 8
// none; the chess set keeps 36 checks at 8 and runs 2.83x (all: 2.78x; it
// kept 5 while a polygon was counted 0.2 a point), and a flat union of 32
// cheap pieces that loses 19% with its checks keeps none.
constexpr double kCheckCost = 8;
// Fewer group steps than this at a union tell too little: no check there.
constexpr double kMinVisits = 24;

struct Group {
  std::array<dvec3, kLanes> p;
  std::array<bool, kLanes> on{};
  bool any() const { return std::any_of(on.begin(), on.end(), [](bool b) { return b; }); }
};

struct ChildStats {
  double visits = 0, evaluations = 0;
};

bool isPlane(const ir::Node& n) {
  return n.kind == ir::NodeKind::Primitive && n.primitive == PrimitiveKind::Plane;
}

class Planner {
 public:
  Planner(const ir::Scene& scene, double threshold) : eval_(scene), threshold_(threshold) {}

  using Lanes = std::array<double, kLanes>;
  static Lanes none() {
    Lanes l;
    l.fill(1e30);
    return l;
  }

  // The group's distances at its points (lanes that are off get nothing).
  // `cut`: what the caller's hard union has so far, as the emitter passes it
  // (GlslEmitter::csg): a hard union skips a child whose box lies beyond it.
  Lanes walk(const ir::Node& n, const Group& g, const Lanes& cut = none()) {
    Lanes out{};
    switch (n.kind) {
      case ir::NodeKind::Union: return unite(n, g, false, cut);
      case ir::NodeKind::Intersect:
      case ir::NodeKind::Subtract: {
        const double k = n.smooth.at(0);
        out = walk(*n.children[0], g);
        for (size_t i = 1; i < n.children.size(); ++i) {
          const std::array<double, kLanes> v = walk(*n.children[i], g);
          for (int l = 0; l < kLanes; ++l) {
            if (!g.on[l]) continue;
            const double b = n.kind == ir::NodeKind::Subtract ? -v[l] : v[l];
            out[l] = k > 0 ? smoothMax(out[l], b, k) : std::max(out[l], b);
          }
        }
        return out;
      }
      case ir::NodeKind::Affine: {
        Group h = g;
        for (int l = 0; l < kLanes; ++l) h.p[l] = n.linear * g.p[l] + n.offset;
        out = walk(*n.children[0], h, keepsDistances(n) ? cut : none());
        for (double& d : out) d *= n.scale;
        return out;
      }
      case ir::NodeKind::Reflect: {
        Group h = g;
        const dvec3 nn = n.vec.value();
        for (int l = 0; l < kLanes; ++l) {
          const double side = glm::dot(g.p[l], nn) - n.amount.value;
          if (side < 0) h.p[l] = g.p[l] - 2 * side * nn;
        }
        return walk(*n.children[0], h, cut);
      }
      default:
        // Anything else is evaluated whole: no check is planned inside it.
        for (int l = 0; l < kLanes; ++l)
          if (g.on[l]) {
            out[l] = eval_.evalNode(n, g.p[l], -1).distance;
            work_ += n.cost;
          }
        return out;
    }
  }

  Lanes unite(const ir::Node& n, const Group& g, bool skip_planes = false, const Lanes& cut_in = none()) {
    const double k = n.smooth.at(0);
    const bool hard = n.smooth.isConst() && n.smooth.value <= 0;
    const Lanes cut = hard ? cut_in : none();
    Lanes acc = none();
    for (const ir::NodeRef& cref : n.children) {
      const ir::Node& c = *cref;
      if (skip_planes && isPlane(c)) continue;
      std::array<double, kLanes> v{};
      if (boxCheckCandidate(c, threshold_)) {
        const double stretch = stretchBelow(c);
        // As the emitter: the group skips the child when no lane is nearer its
        // box than the union so far (+ k), or when every lane that is lies
        // beyond the margin, where the box distance stands in for the child.
        const double margin = boxCheckMargin(c) + k;
        std::array<double, kLanes> b{};
        bool near = false, inner = false;
        for (int l = 0; l < kLanes; ++l) {
          if (!g.on[l]) continue;
          b[l] = c.bounds.distance(g.p[l]) / stretch;
          near = near || b[l] < std::min(acc[l], cut[l]) + k;
          inner = inner || b[l] <= margin;
        }
        ChildStats& s = stats_[&c];
        s.visits += 1;
        work_ += 1;
        v = b;  // beyond the margin, or at least the union so far plus k
        Lanes reach = none();
        if (hard)
          for (int l = 0; l < kLanes; ++l) reach[l] = std::min(acc[l], cut[l]);
        if (near && inner) {
          s.evaluations += 1;
          const Lanes exact = walk(c, g, reach);
          for (int l = 0; l < kLanes; ++l)
            if (b[l] <= margin) v[l] = exact[l];
        }
      } else {
        Lanes reach = none();
        if (hard)
          for (int l = 0; l < kLanes; ++l) reach[l] = std::min(acc[l], cut[l]);
        v = walk(c, g, reach);
      }
      for (int l = 0; l < kLanes; ++l)
        if (g.on[l]) acc[l] = k > 0 ? smoothMin(acc[l], v[l], k) : std::min(acc[l], v[l]);
    }
    return acc;
  }

  const std::unordered_map<const ir::Node*, ChildStats>& stats() const { return stats_; }
  double work() const { return work_; }
  const Evaluator& evaluator() const { return eval_; }

 private:
  Evaluator eval_;
  double threshold_;
  std::unordered_map<const ir::Node*, ChildStats> stats_;
  double work_ = 0;
};

// A deterministic number in [0, 1) for the bounce directions.
double unitHash(uint32_t x) { return (mix32(x) >> 8) * (1.0 / 16777216.0); }

// Whether the walk can reach a union child the emitter could check.
bool hasCandidate(const ir::Node& n, double threshold) {
  switch (n.kind) {
    case ir::NodeKind::Union:
      for (const ir::NodeRef& c : n.children)
        if (boxCheckCandidate(*c, threshold) || hasCandidate(*c, threshold)) return true;
      return false;
    case ir::NodeKind::Intersect:
    case ir::NodeKind::Subtract:
    case ir::NodeKind::Affine:
    case ir::NodeKind::Reflect:
      for (const ir::NodeRef& c : n.children)
        if (hasCandidate(*c, threshold)) return true;
      return false;
    default: return false;
  }
}

}  // namespace

BoundsPlan planBoundChecks(ir::Scene& scene, const MarchPolicy& policy, double cost_threshold, double budget) {
  BoundsPlan plan;
  if (!scene.root || !hasCandidate(*scene.root, cost_threshold)) return plan;
  const MarchLimits limits = deriveMarchLimits(scene, policy);
  const int height = policy.image_height > 0 ? policy.image_height : scene.render.height;
  const int width = std::max(1, int(std::lround(double(scene.render.width) * height / std::max(1, scene.render.height))));
  const ir::Camera& cam = scene.camera;
  const dvec3 eye = cam.position - scene.origin;
  const dvec3 forward = glm::normalize(cam.target - cam.position);
  const dvec3 right = glm::normalize(glm::cross(forward, cam.up));
  const dvec3 up = glm::cross(right, forward);
  const double tan_half = std::tan(glm::radians(cam.fov_degrees) / 2);
  const double aspect = double(width) / height;

  Planner planner(scene, cost_threshold);
  const ir::Node& root = *scene.root;
  // As the emitter: planes at the root are analytic, and the rest lies in a box.
  const bool root_union = root.kind == ir::NodeKind::Union;
  std::vector<const ir::Node*> planes;
  Aabb box = root.bounds;
  if (root_union) {
    box = Aabb();
    for (const ir::NodeRef& c : root.children) {
      if (isPlane(*c)) planes.push_back(c.get());
      else box = box.unite(c->bounds);
    }
  }
  if (box.empty() || !box.finite()) box = Aabb::infinite();
  auto epsilon = [&](double t) { return std::max(limits.hit_epsilon, t * limits.pixel_cone); };
  // March a group in lockstep from `from` along `dir` per lane; hits come back.
  auto march = [&](Group g, std::array<dvec3, kLanes> dir, int max_steps, std::array<bool, kLanes>* hit,
                   std::array<dvec3, kLanes>* where) {
    std::array<double, kLanes> t{};
    const std::array<dvec3, kLanes> from = g.p;
    for (int step = 0; step < max_steps && g.any() && planner.work() < budget; ++step) {
      // The kernel marches only inside the box of the marched part, and
      // intersects the scene's planes in closed form.
      Group inside = g;
      std::array<double, kLanes> d{};
      for (int l = 0; l < kLanes; ++l) {
        if (!g.on[l]) continue;
        const double to_box = box.distance(g.p[l]);
        inside.on[l] = to_box <= 0;
        // Outside the box: a step into it, never a hit on its face.
        d[l] = inside.on[l] ? 1e30 : to_box + 2 * epsilon(t[l]);
        for (const ir::Node* plane : planes)
          d[l] = std::min(d[l], planner.evaluator().evalNode(*plane, g.p[l], -1).distance);
      }
      if (inside.any()) {
        const std::array<double, kLanes> v = root_union ? planner.unite(root, inside, true) : planner.walk(root, inside);
        for (int l = 0; l < kLanes; ++l)
          if (inside.on[l]) d[l] = std::min(d[l], v[l]);
        ++plan.group_steps;
      }
      for (int l = 0; l < kLanes; ++l) {
        if (!g.on[l]) continue;
        if (!std::isfinite(d[l]) || d[l] < epsilon(t[l])) {
          g.on[l] = false;
          if (hit && std::isfinite(d[l])) {
            (*hit)[l] = true;
            (*where)[l] = g.p[l];
          }
          continue;
        }
        t[l] += d[l] * limits.step_scale;
        if (t[l] > limits.max_distance) {
          g.on[l] = false;
          continue;
        }
        g.p[l] = from[l] + t[l] * dir[l];
      }
    }
  };

  // Primary rays that never enter the box cost the kernel nothing: the tiles
  // go where the box's corners project (the whole image if one is behind the
  // camera or the box is unbounded).
  const int tiles_x = std::max(1, width / 4), tiles_y = std::max(1, height / 2);
  int x0 = 0, x1 = tiles_x, y0 = 0, y1 = tiles_y;
  if (box.finite()) {
    double lo_x = 1e30, hi_x = -1e30, lo_y = 1e30, hi_y = -1e30;
    bool behind = false;
    for (int corner = 0; corner < 8; ++corner) {
      const dvec3 q((corner & 1) ? box.hi.x : box.lo.x, (corner & 2) ? box.hi.y : box.lo.y,
                    (corner & 4) ? box.hi.z : box.lo.z);
      const dvec3 v = q - eye;
      const double z = glm::dot(v, forward);
      if (z <= 1e-9 * glm::length(v)) {
        behind = true;
        break;
      }
      const double sx = (glm::dot(v, right) / z / (aspect * tan_half) + 1) / 2 * width;
      const double sy = (1 - glm::dot(v, up) / z / tan_half) / 2 * height;
      lo_x = std::min(lo_x, sx), hi_x = std::max(hi_x, sx), lo_y = std::min(lo_y, sy), hi_y = std::max(hi_y, sy);
    }
    if (!behind) {
      x0 = std::clamp(int(std::floor(lo_x / 4)), 0, tiles_x - 1), x1 = std::clamp(int(std::ceil(hi_x / 4)), x0 + 1, tiles_x);
      y0 = std::clamp(int(std::floor(lo_y / 2)), 0, tiles_y - 1), y1 = std::clamp(int(std::ceil(hi_y / 2)), y0 + 1, tiles_y);
    }
  }
  // Up to 8 x 8 tiles of 4 x 2 pixels in a scattered order (bit-reversed rows
  // and columns), so a budget that ends early still covers the picture.
  const int grid = 8;
  uint32_t tile_index = 0;
  for (int a = 0; a < grid * grid && planner.work() < budget; ++a) {
    int rx = 0, ry = 0;  // bit-reversed 3-bit coordinates
    for (int bit = 0; bit < 3; ++bit) {
      rx |= ((a >> bit) & 1) << (2 - bit);
      ry |= ((a >> (bit + 3)) & 1) << (2 - bit);
    }
    const int tx = std::min(x1 - 1, x0 + (2 * rx + 1) * (x1 - x0) / (2 * grid));
    const int ty = std::min(y1 - 1, y0 + (2 * ry + 1) * (y1 - y0) / (2 * grid));
    Group g;
    std::array<dvec3, kLanes> dir;
    for (int l = 0; l < kLanes; ++l) {
      const double px = tx * 4 + (l % 4) + 0.5, py = ty * 2 + (l / 4) + 0.5;
      const double u = (2 * px / width - 1) * aspect * tan_half, v = (1 - 2 * py / height) * tan_half;
      dir[l] = glm::normalize(forward + u * right + v * up);
      g.p[l] = eye;
      g.on[l] = true;
    }
    std::array<bool, kLanes> hit{};
    std::array<dvec3, kLanes> at;
    march(g, dir, 256, &hit, &at);
    // From each hit, a shadow ray and a bounce, as the path tracer's first
    // vertex sends (deeper bounces look like the first).
    Group shadow, bounce;
    std::array<dvec3, kLanes> to_light, diffuse;
    for (int l = 0; l < kLanes; ++l) {
      if (!hit[l]) continue;
      dvec3 n = planner.evaluator().gradient(at[l], 1e-6 * std::max(1.0, glm::length(at[l])));
      n = glm::length(n) > 0 ? glm::normalize(n) : -dir[l];
      const dvec3 start = at[l] + n * (4 * epsilon(glm::length(at[l] - eye)));
      to_light[l] = scene.sun ? scene.sun->direction
                    : !scene.lights.empty() ? glm::normalize(scene.lights[0].position - scene.origin - start + dvec3(1e-12))
                                            : dvec3(0, 1, 0);
      const double r1 = unitHash(tile_index * 16 + l), r2 = unitHash(tile_index * 16 + l + 8);
      const dvec3 helper = std::abs(n.x) > 0.9 ? dvec3(0, 1, 0) : dvec3(1, 0, 0);
      const dvec3 tu = glm::normalize(glm::cross(n, helper)), tv = glm::cross(n, tu);
      const double phi = 2 * M_PI * r1, s = std::sqrt(r2);
      diffuse[l] = glm::normalize(tu * (s * std::cos(phi)) + tv * (s * std::sin(phi)) + n * std::sqrt(1 - r2));
      shadow.p[l] = bounce.p[l] = start;
      shadow.on[l] = bounce.on[l] = true;
    }
    march(shadow, to_light, 128, nullptr, nullptr);
    march(bounce, diffuse, 128, nullptr, nullptr);
    ++tile_index;
  }
  plan.tiles = int(tile_index);

  // Decide per child, on every node the walk reached.
  for (const auto& [node, s] : planner.stats()) {
    ++plan.candidates;
    if (s.visits < kMinVisits) continue;
    const double skipped = 1 - s.evaluations / s.visits;
    const double saving = skipped * node->cost - kCheckCost;
    ir::Node& n = const_cast<ir::Node&>(*node);  // the scene is ours to mark
    n.box_check_skips = skipped;
    if (saving > 0) {
      n.box_check = true;
      ++plan.checks;
    }
    plan.saved += s.visits * std::max(saving, 0.0);
  }
  plan.work = planner.work();
  return plan;
}

}  // namespace sdfc
