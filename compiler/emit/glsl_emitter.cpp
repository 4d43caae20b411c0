#include "emit/glsl_emitter.h"

#include <cctype>
#include <cmath>
#include <functional>
#include <glm/gtc/quaternion.hpp>
#include <iterator>
#include <map>
#include <optional>
#include <sstream>
#include <unordered_set>

#include "emit/color_field_glsl.h"
#include "emit/embedded_sources.h"
#include "emit/env_map_glsl.h"
#include "emit/feature_filter.h"
#include "meshin/mesh_exact.h"
#include "passes/deform.h"
#include "shapes/polygon.h"

namespace sdfc {

std::string glslFloat(double v) {
  if (v == 0) return "0.0";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  std::string s = buf;
  if (s.find_first_of(".eE") == std::string::npos) s += ".0";
  if (s.find("inf") != std::string::npos) s = v > 0 ? "1e30" : "-1e30";
  return s;
}

namespace {

std::vector<bool> usedMaterials(const ir::Scene& scene, bool& unassigned);

using glm::dvec3;

// Hierarchy visits per evaluation when the scene code is emitted without the
// kernel (test shaders): with the kernel the renderer sets frame.traversal_visits.
// Enough that a blend list of up to 63 members is folded from its list, as
// the kernel does where loops are not capped (with 256, lists beyond 15 took
// the hierarchy, whose fold is in visit order), and within 22.3.6's 65,535
// iterations for the few evaluations a test shader makes.
constexpr int kSceneOnlyVisits = 4096;
// A hierarchy node nearest of all left on the stack, whose box is farther than
// this times its diagonal, ends the traversal with its box distance d: the true
// distance D is then at most d + diagonal <= 2d, a march step at least half of
// D, and steps near surfaces (where boxes are near) stay exact.
constexpr double kFarBoxFactor = 1.0;
// Stack entries a visit may drop after its work when they cannot hold
// anything nearer than the best so far.
constexpr int kPrunesPerVisit = 3;
// Grid lists copy one-vec4 records up to this size (16 bytes per listed
// instance); beyond it they hold 4-byte indices, which keeps a million
// instances' data (76 MB) within lavapipe's 128 MiB storage buffer range.
constexpr size_t kMaxCopiedRecordBytes = size_t(32) << 20;
// The root sphere cloud's fixed slots, where all the scene's data then stays
// within kMaxSlotDataBytes, under the 128 MiB storage buffer range every
// Vulkan device has (a million spheres: 122 MB, their grid capped at 800,000
// cells by instance_grid.cpp); else index lists. Each cell's kGridListMax
// centres are packed as 24 floats (kPackedSlotVec4 vec4) when the scene has
// one material; else they are records, a vec4 each, whose w is the material.
constexpr int kPackedSlotVec4 = ir::kGridListMax * 3 / 4;
constexpr size_t kMaxSlotDataBytes = size_t(124) << 20;
// --count-event quantities (kCountEventQuantities) the scene code counts.
constexpr int kEventLookups = 2, kEventEntries = 3, kEventVisits = 4;

// A plain variable name (not a call or other expression), safe to repeat.
bool isIdentifier(const std::string& s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) return false;
  return true;
}

std::string vec3Literal(dvec3 v) {
  if (v.x == v.y && v.y == v.z) return "vec3(" + glslFloat(v.x) + ")";
  return "vec3(" + glslFloat(v.x) + ", " + glslFloat(v.y) + ", " + glslFloat(v.z) + ")";
}

const char* kRotateHelper = R"(// p rotated by -angle about the unit axis (Rodrigues): the inverse map of a rotation.
vec3 sdRotateInverse(vec3 p, vec3 axis, float angle) {
  float c = cos(angle), s = sin(angle);
  return p * c - cross(axis, p) * s + axis * dot(axis, p) * (1.0 - c);
}
)";
const char* kSmoothHelpers = R"(// Polynomial smooth minimum (Quilez): lowers min(a, b) by at most k/4.
float sdSmoothMin(float a, float b, float k) {
  float h = max(k - abs(a - b), 0.0) / k;
  return min(a, b) - h * h * k * 0.25;
}
float sdSmoothMax(float a, float b, float k) { return -sdSmoothMin(-a, -b, k); }
)";
const char* kBoxDistanceHelper = R"(// Distance from p to the box [lo, hi] (0 inside): a lower bound on the
// distance to anything in it.
float sdBoxDistance(vec3 p, vec3 lo, vec3 hi) {
  return length(max(max(lo - p, p - hi), 0.0));
}
)";
const char* kSignedBoxDistanceHelper = R"(// Signed distance from p to the box [lo, hi], negative inside: a lower
// bound on anything in it, inside too (a shape within the box is no deeper
// at p than the box is), which a union's interior values need.
float sdBoxSignedDistance(vec3 p, vec3 lo, vec3 hi) {
  vec3 e = max(lo - p, p - hi);
  return length(max(e, 0.0)) + min(max(e.x, max(e.y, e.z)), 0.0);
}
)";
const char* kAabbHelper = R"(// Distance to an axis-aligned box from outside (0 inside): a cheap lower bound
// on the distance to anything the box contains.
float sdBound(vec3 p, vec3 center, vec3 half_size) {
  return length(max(abs(p - center) - half_size, 0.0));
}
)";

// Which single material a subtree's surfaces carry, given the inherited one;
// kMixed when they differ.
constexpr int kMixed = -2;

// Set n's templates, each once per distinct material its copies carry (a
// copy's own material is in the set's data, not on a node; a million copies
// share a few): visit(template, material) until it returns false.
template <typename Visit>
void eachTemplateMaterial(const ir::Node& n, int inherited, Visit visit) {
  std::set<std::pair<int, int>> seen;
  for (const ir::Instance& inst : n.instances->instances) {
    const int m = inst.material >= 0 ? inst.material : inherited;
    if (seen.insert({m, inst.templ}).second && !visit(*n.children[inst.templ], m)) return;
  }
}

int uniformMaterial(const ir::Node& n, int inherited) {
  const int mine = n.material >= 0 ? n.material : inherited;
  if (n.children.empty()) return mine;
  if (n.kind == ir::NodeKind::Instances) {
    int common = kMixed - 1;
    eachTemplateMaterial(n, mine, [&](const ir::Node& templ, int m) {
      const int u = uniformMaterial(templ, m);
      common = common == kMixed - 1 || u == common ? u : kMixed;
      return common != kMixed;
    });
    return common == kMixed - 1 ? mine : common;
  }
  int common = uniformMaterial(*n.children[0], mine);
  for (size_t i = 1; i < n.children.size() && common != kMixed; ++i) {
    if (n.kind == ir::NodeKind::Subtract) break;  // cut faces take the first child's material
    if (uniformMaterial(*n.children[i], mine) != common) common = kMixed;
  }
  return common;
}

// Hierarchy traversals one evaluation of `n` may make (the renderer divides
// the loop cap's room by it): a set inside a repeat's neighbour cells or in
// several uses of a definition counts once per evaluation of it.
// `free_set`: Instances nodes whose evaluations never reach their hierarchy.
int traversalsPerEvaluation(const ir::Node& n, const ir::Node* free_set) {
  if (n.kind == ir::NodeKind::Instances) return &n == free_set ? 0 : 1;
  // An exact mesh's triangle search is a hierarchy loop as the instances' are.
  if (n.kind == ir::NodeKind::Mesh) return n.mesh->mode == MeshMode::Exact ? 1 : 0;
  int sum = 0;
  for (const ir::NodeRef& c : n.children) sum += traversalsPerEvaluation(*c, free_set);
  if (n.kind == ir::NodeKind::RepeatPolar && n.count.x > 1) {
    const PolarSectors s = polarSectors(n);
    sum *= s.last - s.first + 1;
  }
  if (n.kind == ir::NodeKind::Repeat && sum > 0)
    for (int a = 0; a < 3; ++a) sum *= 2 * repeatCells(n, a).side + 1;
  return sum;
}

class SceneWriter {
 public:
  SceneWriter(const ir::Scene& scene, const EmitOptions& options)
      : scene_(scene), options_(options) {}

  // Returns the scene code: helper and primitive functions, definitions,
  // sdScene, sdSceneMaterial, sdMaterialId, sdMaterial, sdSky and the constants.
  std::string write(const MarchLimits& limits, EmitStats& stats) {
    // Planes directly in the scene are intersected analytically by the
    // kernel, not marched: a ray grazing a ground plane would otherwise crawl
    // toward the horizon in tiny steps, and every evaluation pays for them.
    ir::Node root = *scene_.root;
    if (options_.with_kernel && options_.analytic_planes && root.kind == ir::NodeKind::Union &&
        root.smooth.isConst() && root.smooth.value == 0) {
      std::vector<ir::NodeRef> kept;
      for (const ir::NodeRef& c : root.children) {
        if (options_.analytic_spheres && spheres_.size() < 8 && takeSphere(*c, root.material)) continue;
        bool constant = c->kind == ir::NodeKind::Primitive && c->primitive == PrimitiveKind::Plane &&
                        c->definition.empty();
        for (const ir::Scalar& a : c->args) constant = constant && a.isConst();
        if (!constant || planes_.size() >= 8) {
          kept.push_back(c);
          continue;
        }
        const dvec3 n = glm::normalize(dvec3(c->args[0].value, c->args[1].value, c->args[2].value));
        const int material = c->material >= 0 ? c->material : std::max(root.material, 0);
        planes_.push_back({n, c->args[3].value, material, c->range.line()});
      }
      if (!planes_.empty() || !spheres_.empty()) {
        for (const ir::NodeRef& c : root.children)
          if (std::find(kept.begin(), kept.end(), c) == kept.end()) taken_.insert(c.get());
        root.children = kept;
        if (kept.empty()) {
          // Nothing left to march: a primitive far outside the view stands in.
          auto far = std::make_shared<ir::Node>();
          far->kind = ir::NodeKind::Primitive;
          far->primitive = PrimitiveKind::Sphere;
          far->args = {ir::constant(1)};
          auto moved = std::make_shared<ir::Node>();
          moved->kind = ir::NodeKind::Affine;
          moved->offset = dvec3(-1e30);
          moved->children = {far};
          root.children = {moved};
        }
      }
    }
    // The root's grid may tell march() how far the ray can go with no
    // surface, when the set is all the marched scene is (docs/design/large_scenes.md).
    if (options_.with_kernel) {
      const ir::Node* only = &root;
      if (root.kind == ir::NodeKind::Union && root.smooth.isConst() && root.smooth.value == 0 &&
          root.children.size() == 1)
        only = root.children[0].get();
      if (only->kind == ir::NodeKind::Instances && !only->instances->grid.empty() && !only->instances->grid.blend)
        ray_skip_set_ = only;
      // One material: sdSceneMaterial reads none, so the slots need no w.
      packed_slots_ = uniformMaterial(root, -1) != kMixed;
    }
    // `--prune`: the root's parts pruned per cell.
    if (options_.with_kernel && options_.prune && scene_.root->prune && root.kind == ir::NodeKind::Union) {
      prune_ = scene_.root->prune.get();
      prune_root_ = &root;
      pruneGridData();
    }
    // Distance function.
    {
      Function f = beginFunction("float sdScene(vec3 p)");
      const std::string d = node(root, "p", f, false, "-1");
      f.code << "  return " << d << ";\n}\n";
      functions_ << f.code.str();
    }
    // Distance and material id of the nearest surface in one evaluation: the
    // kernel's normal taps call it, so the scene is inlined there once for both
    // (a separate sdMaterialId call site was a whole further inlined copy).
    // Its distance is sdScene's: the same operations (bounding volumes aside,
    // whose box distances stand in only far from every surface).
    const int uniform = uniformMaterial(root, -1);
    {
      std::ostringstream f;
      if (uniform != kMixed) {
        f << "vec2 sdSceneMaterial(vec3 p) { return vec2(sdScene(p), " << glslFloat(std::max(uniform, 0))
          << "); }\n";
        // march() then reads the normal taps' material from it, not from a
        // second (inlined) call site of the scene (SDFC_ONE_MATERIAL).
        f << "const int kSceneMaterial = " << std::max(uniform, 0) << ";\n";
        one_material_ = true;
      } else {
        Function fn = beginFunction("vec2 sdSceneMaterial(vec3 p)");
        const std::string dm = node(root, "p", fn, true, "-1.0");
        fn.code << "  return " << dm << ";\n}\n";
        f << fn.code.str();
      }
      f << "int sdMaterialId(vec3 p) { return int(sdSceneMaterial(p).y); }\n";
      if (has_sphere_normals_ && uniform != kMixed) {
        // The root grid's spheres are the whole marched scene and of one
        // material: a sphere normal needs no evaluation to read it.
        has_sphere_material_ = true;
        f << "const int kRootSphereMaterial = " << std::max(uniform, 0) << ";\n";
      }
      functions_ << f.str();
    }
    stats.bounded_subtrees = bounded_;
    stats.functions = function_count_;
    // The marched part's box: the root's bounds, or with planes taken out,
    // the union of what is left (the far placeholder has none: no box).
    Aabb box = root.bounds;
    if (!planes_.empty() || !spheres_.empty()) {
      box = Aabb();
      for (const ir::NodeRef& c : root.children) box = box.unite(c->bounds);
    }
    // Padded by a few hit epsilons and float32 ulps of its corners.
    const double pad = 4 * limits.hit_epsilon +
                       8 * std::ldexp(1.0, -23) * std::max(glm::length(box.lo), glm::length(box.hi));
    has_scene_box_ = options_.with_kernel && options_.scene_box && !box.empty() && box.finite();

    std::ostringstream out;
    out << "// ---- scene constants (derived per scene by the compiler) ----\n";
    out << "const float kSceneMaxDist = " << glslFloat(limits.max_distance) << ";\n";
    out << "const int kSceneMaxSteps = " << limits.max_steps << ";\n";
    out << "const float kSceneHitEps = " << glslFloat(limits.hit_epsilon) << ";\n";
    out << "const float kScenePixelCone = " << glslFloat(limits.pixel_cone) << ";\n";
    out << "const float kSceneStepScale = " << glslFloat(limits.step_scale) << ";\n";
    if (has_scene_box_) {
      const Aabb b = box.grow(pad);
      out << "// The marched part of the scene lies in this box.\n";
      out << "const vec3 kSceneBoxLo = vec3(" << glslFloat(b.lo.x) << ", " << glslFloat(b.lo.y) << ", "
          << glslFloat(b.lo.z) << ");\n";
      out << "const vec3 kSceneBoxHi = vec3(" << glslFloat(b.hi.x) << ", " << glslFloat(b.hi.y) << ", "
          << glslFloat(b.hi.z) << ");\n";
    }
    lights(out);
    if (hasAnalyticPlanes()) analyticSurfaces(out);
    {
      bool unassigned = false;
      texture_bases_ = appendTextureData(scene_, usedMaterials(scene_, unassigned), data_);
    }
    if (scene_.sky.map) env_map_ = appendEnvMapData(scene_.sky, data_);
    if (!data_.empty()) {
      out << "\n// Instance hierarchies and records (the runtime binds the compiler's scene data).\n";
      out << "layout(std430, set = 0, binding = 0) readonly buffer SdfcSceneData { vec4 sd_data[]; };\n";
    }
    if (!options_.count_event.empty()) countEventDeclarations(out);
    if (ray_skip_set_) {
      out << "\n// The ray march() steps along; the root grid's lookup writes how far it may\n"
             "// go from p with no surface (0: no more than the distance).\n";
      out << "// g_ray_met: a sphere's surface lies exactly at g_ray_skip (its analytic hit).\n";
      out << "vec3 g_ray_dir = vec3(0.0);\nfloat g_ray_skip = 0.0;\nbool g_ray_met = false;\n";
      if (has_sphere_hit_) {
        out << "// g_ray_met_slot: that sphere's slot; g_hit_sphere: the slot of the sphere the\n"
               "// last march() ended on by its analytic hit, or -1 (sdRootSphereNormal).\n";
        out << "int g_ray_met_slot = -1;\nint g_hit_sphere = -1;\n";
        out << "// g_ray_any: the nearest listed sphere's hit along the ray, wherever it lies;\n"
               "// g_ray_any_hit: the ray marched is a shadow ray (any hit blocks it).\n";
        out << "float g_ray_any = 1e30;\nbool g_ray_any_hit = false;\n";
      }
    }
    out << "\n// ---- scene helpers and primitives (only those the scene uses) ----\n";
    out << helpers_.str();
    out << "\n// ---- scene distance ----\n";
    out << functions_.str();
    materials(out);
    sky(out, stats.features);
    return out.str();
  }

 private:
  struct Function {
    std::ostringstream code;
    int next_var = 0;
  };

  const ir::Scene& scene_;
  const EmitOptions& options_;
  std::ostringstream helpers_;
  std::ostringstream functions_;
  std::set<std::string> helper_names_;
  std::map<std::string, std::string> polygon_names_;  // point list -> its function
  struct AnalyticPlane {
    dvec3 normal;
    double offset;
    int material;
    int line;
  };
  std::vector<AnalyticPlane> planes_;
  struct AnalyticSphere {
    dvec3 center;
    double radius;
    int material;
    int line;
  };
  std::vector<AnalyticSphere> spheres_;
  bool has_scene_box_ = false;
  EnvMapLayout env_map_;  // where sky(map: ...)'s data lie (when it has one)
  // The instance set whose grid computes g_ray_skip (SDFC_HAS_RAY_SKIP), if any.
  const ir::Node* ray_skip_set_ = nullptr;
  bool packed_slots_ = false;  // its fixed slots hold centres only (kPackedSlotVec4 a cell)
  bool has_sphere_normals_ = false;  // sdRootSphereNormal was emitted
  bool one_material_ = false;  // kSceneMaterial: sdSceneMaterial's material is one constant
  bool has_sphere_material_ = false;  // and kRootSphereMaterial: the scene has one material
  bool has_sphere_hit_ = false;  // march() keeps the slot of a met sphere (g_hit_sphere)
  bool has_glass_ = false;  // the scene uses glass (SDFC_HAS_GLASS): planes take contact rays
  // Root children the kernel intersects in closed form (planes, spheres): out of the union.
  std::unordered_set<const ir::Node*> taken_;
  // The root union's prune grid (passes/prune_grid.cpp) when used, the root
  // it prunes, and where its masks start in the scene data (in vec4s).
  const ir::PruneGrid* prune_ = nullptr;
  const ir::Node* prune_root_ = nullptr;
  int pruned_checks_ = 0;
  // What the caller's hard union has so far, for the node emitted next: a
  // value at or above it cannot lower that union (see csg); "" where there is
  // no such caller. node() takes it, so only the node emitted next sees it.
  std::string cut_;

  // The masks as vec4s of exact integers (24 bits a float: the web page's
  // float texture reads them too), and sdPruneMask, which looks p's up:
  // every bit outside the grid (and for a NaN point).
  void pruneGridData() {
    const size_t base = data_.size() / 4;
    for (const auto& m : prune_->masks) pushVec4(float(m[0]), float(m[1]), float(m[2]), float(m[3]));
    const ir::PruneGrid& g = *prune_;
    const std::string index = std::to_string(base) + " + c.x + " + std::to_string(g.dims.x) + " * (c.y + " +
                              std::to_string(g.dims.y) + " * c.z)";
    std::ostringstream h;
    h << "// The parts of the scene's union each cell needs (passes/prune_grid.cpp):\n"
         "// 24 bits a component; every part outside the grid.\n"
         "uvec4 sdPruneMask(vec3 p) {\n"
         "  vec3 g = (p - "
      << vec3Literal(g.lo) << ") * " << glslFloat(1 / g.cell) << ";\n"
      << "  const vec3 dims = vec3(" << g.dims.x << ".0, " << g.dims.y << ".0, " << g.dims.z << ".0);\n"
      << "  bool inside = all(greaterThanEqual(g, vec3(0.0))) && all(lessThan(g, dims));\n"
      << "  ivec3 c = clamp(ivec3(g), ivec3(0), ivec3(dims) - 1);\n";
    h << "  uvec4 m = uvec4(sd_data[" << index << "]);\n";
    h << "  return inside ? m : uvec4(0xFFFFFFu);\n"
      << "}\n";
    prune_helper_ = h.str();
  }
  std::string prune_helper_;

  // A top-level sphere with constant radius, bare or under one Affine that is
  // a similarity (scale * linear orthonormal), of a non-emissive material in a
  // scene without glass: recorded in spheres_ (true) or left to the march (false).
  bool takeSphere(const ir::Node& c, int root_material) {
    const ir::Node* sphere = &c;
    dvec3 center(0.0);
    double radius_scale = 1.0;
    int material = c.material;
    if (c.kind == ir::NodeKind::Affine && c.children.size() == 1 && c.definition.empty()) {
      sphere = c.children[0].get();
      // local = linear * p + offset, d = scale * child(local): a sphere of
      // radius scale * r about linear^-1 * (-offset) when scale * linear is a rotation.
      const glm::dmat3 rotation = c.linear * c.scale;
      const glm::dmat3 gram = glm::transpose(rotation) * rotation;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          if (std::abs(gram[i][j] - (i == j ? 1.0 : 0.0)) > 1e-9) return false;
      center = glm::inverse(c.linear) * -c.offset;
      radius_scale = c.scale;
      if (sphere->material >= 0) material = sphere->material;
    }
    if (sphere->kind != ir::NodeKind::Primitive || sphere->primitive != PrimitiveKind::Sphere ||
        !sphere->definition.empty() || sphere->args.size() != 1 || !sphere->args[0].isConst())
      return false;
    if (material < 0) material = std::max(root_material, 0);
    if (material < static_cast<int>(scene_.materials.size()) &&
        scene_.materials[material].model == ir::MaterialModel::Emissive)
      return false;
    // A ray inside marched glass (march side -1) does not see analytic
    // surfaces: glass touching or overlapping the sphere would let it through.
    for (const ir::Material& m : scene_.materials)
      if (m.model == ir::MaterialModel::Glass) return false;
    const double radius = sphere->args[0].value * radius_scale;
    if (!(radius > 0) || !std::isfinite(radius)) return false;
    spheres_.push_back({center, radius, material, c.range.line()});
    return true;
  }

  // sdPlanesHit (the nearest analytic surface the ray enters, index: planes
  // first, then spheres) and sdAnalyticNormal (its normal and material).
  // Straight-line code, not loops: loops count against lavapipe's cap.
  void analyticSurfaces(std::ostream& out) const {
    out << "// Surfaces intersected analytically (line";
    for (const auto& pl : planes_) out << " " << pl.line;
    for (const auto& sp : spheres_) out << " " << sp.line;
    out << "): planes (dot(p, n) <= offset is solid), then spheres.\n";
    out << "// Nearest hit from outside a solid, or 3e38; `index` names it.\n";
    out << "float sdPlanesHit(vec3 ro, vec3 rd, out int index) {\n  float t = 3.0e38;\n  index = -1;\n";
    int index = 0;
    // With glass, a ray that left a glass resting on the plane starts a ray
    // offset below it, heading in: it meets the plane at once (t = 0), as a
    // thin air gap's light meets the floor (docs/design/glass_contact.md).
    // Only within 1% of the scale: a ray far below is no such ray.
    const std::string above = has_glass_ ? "h > -0.01 * (1.0 + max(abs(ro.x), max(abs(ro.y), abs(ro.z))))" : "h > 0.0";
    const std::string hit_t = has_glass_ ? "max(-h / c, 0.0)" : "-h / c";
    for (const auto& pl : planes_) {
      const std::string n = vec3Literal(pl.normal);
      out << "  {\n    float c = dot(rd, " << n << "), h = dot(ro, " << n << ") - " << glslFloat(pl.offset)
          << ";\n    if (c < 0.0 && " << above << " && " << hit_t << " < t) {\n      t = " << hit_t
          << ";\n      index = " << index++ << ";\n    }\n  }\n";
    }
    for (const auto& sp : spheres_) {
      // From outside (c > 0) and heading in (b < 0): the near root. A ray
      // leaving the surface it starts on has b >= 0 and no hit. In float32,
      // b * b - c loses r^2 next to |oc|^2 for a far sphere: the discriminant is
      // r^2 minus the squared distance from the centre to the ray (Haines et al.,
      // "Precision improvements for ray/sphere intersection", Ray Tracing Gems
      // 2019, ch. 7), and the near root c / q avoids -b - sqrt(disc)'s cancellation.
      out << "  {\n    vec3 oc = ro - " << vec3Literal(sp.center) << ";\n    float b = dot(oc, rd), c = dot(oc, oc) - "
          << glslFloat(sp.radius * sp.radius) << ";\n    vec3 f = oc - b * rd;\n    float disc = "
          << glslFloat(sp.radius * sp.radius) << " - dot(f, f);\n"
          << "    if (b < 0.0 && c > 0.0 && disc >= 0.0) {\n      float ts = c / (-b + sqrt(disc));\n"
          << "      if (ts < t) {\n        t = ts;\n        index = " << index << ";\n      }\n    }\n  }\n";
      ++index;
    }
    out << "  return t;\n}\n";
    out << "vec3 sdAnalyticNormal(int index, vec3 p, out int material) {\n";
    index = 0;
    for (const auto& pl : planes_)
      out << "  if (index == " << index++ << ") { material = " << pl.material << "; return "
          << vec3Literal(pl.normal) << "; }\n";
    for (const auto& sp : spheres_)
      out << "  if (index == " << index++ << ") { material = " << sp.material << "; return normalize(p - "
          << vec3Literal(sp.center) << "); }\n";
    out << "  material = 0;\n  return vec3(0.0, 1.0, 0.0);\n}\n";
  }

 public:
  void setGlass(bool glass) { has_glass_ = glass; }
  bool hasAnalyticPlanes() const { return !planes_.empty() || !spheres_.empty(); }
  bool hasSceneBox() const { return has_scene_box_; }
  bool hasRaySkip() const { return ray_skip_set_ != nullptr; }
  bool hasSphereNormals() const { return has_sphere_normals_; }
  bool hasSphereMaterial() const { return has_sphere_material_; }
  bool oneMaterial() const { return one_material_; }
  bool hasSphereHit() const { return has_sphere_hit_; }
  int prunedChecks() const { return pruned_checks_; }

 private:
  std::map<std::pair<const ir::Node*, bool>, std::string> node_functions_;
  struct InstanceLayout {
    int id = 0;
    size_t nodes = 0;    // vec4 index of the hierarchy (2 vec4 per node)
    size_t records = 0;  // vec4 index of instance 0's record
    int stride = 1;      // vec4 per record
    bool affine = false; // records hold a 3x4 map and a scale
    int param_vec4 = 0;  // vec4 of primitive parameters after the placement
    // One parameter and no material of its own (a molecule's radii): it rides
    // in the offset's w, records of one vec4.
    bool param_in_w = false;
    // Affine records of rotations alone (no scale): a unit quaternion, then
    // (offset, template), 2 vec4 instead of 4.
    bool rotor = false;
    // Rotor records of copies with materials of their own: the fourth float
    // is template + 256 (material + 1) (exact in float: at most 256
    // templates and 65,535 materials).
    bool rotor_material = false;
    // A mixed set (several templates): each record carries its template index,
    // in the affine placement's fourth vec4 (scale, material, template, 0)
    // where there is one (templ_in_placement), else after its parameters at
    // float slot set.param_count of the parameter vec4s.
    bool mixed = false;
    bool templ_in_placement = false;
    bool grid = false;   // a grid: header (2 vec4), cells (1 vec4 each), lists (4 per vec4)
    size_t grid_header = 0, grid_cells = 0, grid_entries = 0;
    bool grid_records = false;  // lists hold copies of the records (stride vec4 each), not indices
    // Every cell's list is kGridListMax centres (padded with copies of its
    // last, or a far dummy), slot_vec4 vec4 a cell, tested without a loop (the
    // root's sphere cloud).
    bool grid_slots = false;
    int slot_vec4 = 0;  // kPackedSlotVec4 (centres only) or kGridListMax (records)
  };
  std::map<const ir::Node*, InstanceLayout> instance_layouts_;
  std::vector<float> data_;
  std::map<const ir::TextureImage*, size_t> texture_bases_;  // where each texture's texels start

 public:
  std::vector<float> takeData() { return std::move(data_); }
  int instanceSets() const { return static_cast<int>(instance_layouts_.size()); }
  bool hasExactMesh() const { return exact_mesh_; }
  // The root point cloud of one material when its fixed-slot grid has no
  // crowded cell: its lookups and sphere normals never walk the hierarchy nor
  // loop over a list (sdSceneMaterial is sdScene's distance and a constant),
  // so a pass needs no hierarchy visits for it and may take as many samples
  // as any scene's.
  const ir::Node* traversalFreeSet() const {
    if (!ray_skip_set_ || !has_sphere_hit_ || !has_sphere_material_) return nullptr;
    auto it = instance_layouts_.find(ray_skip_set_);
    if (it == instance_layouts_.end() || !it->second.grid_slots) return nullptr;
    const std::vector<std::int32_t>& count = ray_skip_set_->instances->grid.count;
    if (std::find(count.begin(), count.end(), ir::kGridCrowded) != count.end()) return nullptr;
    return ray_skip_set_;
  }

 private:
  int bounded_ = 0;
  int function_count_ = 0;

  Function beginFunction(const std::string& signature) {
    Function f;
    f.code << signature << " {\n";
    return f;
  }

  void needHelper(const std::string& name, const char* code) {
    if (helper_names_.insert(name).second) helpers_ << code;
  }

  std::string var(Function& f, const char* prefix) {
    return prefix + std::to_string(f.next_var++);
  }

  // A (distance, material) expression used more than once, in a variable.
  std::string keep(Function& f, const std::string& pair) {
    const std::string m = var(f, "m");
    f.code << "  vec2 " << m << " = " << pair << ";\n";
    return m;
  }

  static std::string lineComment(const ir::Node& n) {
    const int line = n.range.line();
    // Always a comment, so the node name callers append stays inside it.
    return line > 0 ? "  // line " + std::to_string(line) : "  //";
  }

  std::string lineDirective(const ir::Node& n) {
    if (!options_.line_directives || !n.range.file) return "";
    return "#line " + std::to_string(n.range.line()) + " \"" + n.range.file->path + "\"\n";
  }

  // Emits `n` evaluated at point variable `p` into `f`. Returns a float
  // expression (distance) or, with `mat`, a vec2 expression (distance,
  // material id). `inherited` is the material id expression from above.
  std::string node(const ir::Node& n, const std::string& p, Function& f, bool mat,
                   const std::string& inherited) {
    const std::string mine = n.material >= 0 ? glslFloat(n.material) : inherited;
    const std::string cut = std::move(cut_);
    cut_.clear();
    // A material-uniform subtree needs no material tracking inside.
    if (mat) {
      const int u = uniformMaterial(n, -3);
      if (u != kMixed) {
        cut_ = cut;
        const std::string d = node(n, p, f, false, mine);
        const std::string m = var(f, "m");
        f.code << "  vec2 " << m << " = vec2(" << d << ", "
               << (u == -3 ? mine : u < 0 ? "-1.0" : glslFloat(u)) << ");\n";
        return m;
      }
    }
    // Named definitions become functions, called at each use.
    if (!n.definition.empty()) return callFunction(n, p, f, mat, mine, "", cut);
    switch (n.kind) {
      case ir::NodeKind::Primitive: return primitive(n, p, f);
      case ir::NodeKind::Union:
      case ir::NodeKind::Intersect:
      case ir::NodeKind::Subtract: return csg(n, p, f, mat, mine, cut);
      case ir::NodeKind::Morph: {
        const std::string a = node(*n.children[0], p, f, mat, mine);
        const std::string b = node(*n.children[1], p, f, mat, mine);
        const std::string t = var(f, "t");
        f.code << "  float " << t << " = " << n.amount.glsl() << ";" << lineComment(n) << " morph\n";
        if (!mat) return "mix(" + b + ", " + a + ", " + t + ")";
        return "vec2(mix(" + b + ".x, " + a + ".x, " + t + "), " + t + " >= 0.5 ? " + a + ".y : " +
               b + ".y)";
      }
      case ir::NodeKind::Instances: return instances(n, p, f, mat, mine);
      case ir::NodeKind::Mesh: return mesh(n, p, f);
      case ir::NodeKind::Round:
      case ir::NodeKind::Shell: {
        const std::string c = node(*n.children[0], p, f, mat, mine);
        const std::string x = mat ? c + ".x" : c;
        const std::string r = var(f, "d");
        const bool shell = n.kind == ir::NodeKind::Shell;
        f.code << "  float " << r << " = " << (shell ? "abs(" + x + ")" : x) << " - " << n.amount.glsl() << ";"
               << lineComment(n) << (shell ? " shell\n" : " round\n");
        return mat ? "vec2(" + r + ", " + c + ".y)" : r;
      }
      case ir::NodeKind::Extrude: {
        // The profile at z = 0, then the 2D box corner of it and the slab.
        const std::string q = var(f, "p");
        f.code << "  vec3 " << q << " = vec3(" << p << ".xy, 0.0);" << lineComment(n) << " extrude\n";
        std::string c = node(*n.children[0], q, f, mat, mine);
        if (mat && !isIdentifier(c)) c = keep(f, c);
        const std::string w = var(f, "w");
        f.code << "  vec2 " << w << " = vec2(" << (mat ? c + ".x" : c) << ", abs(" << p << ".z) - "
               << n.amount.glsl() << ");\n";
        const std::string r = var(f, "d");
        f.code << "  float " << r << " = min(max(" << w << ".x, " << w << ".y), 0.0) + length(max(" << w
               << ", 0.0));\n";
        return mat ? "vec2(" + r + ", " + c + ".y)" : r;
      }
      case ir::NodeKind::Twist:
      case ir::NodeKind::Bend: {
        // As the evaluator: the deformed field over its Lipschitz factor within
        // the radius holding the child, the cylinder's distance outside.
        needHelper("sdBox2", box2Glsl());
        const Aabb& b = n.children[0]->bounds;
        const std::string q = var(f, "p");
        if (n.kind == ir::NodeKind::Twist) {
          needHelper("rotate", kRotateHelper);
          f.code << "  vec3 " << q << " = sdRotateInverse(" << p << ", vec3(0.0, 1.0, 0.0), radians("
                 << n.amount.glsl() << " * " << p << ".y));" << lineComment(n) << " twist\n";
        } else {
          const std::string a = var(f, "a");
          f.code << "  float " << a << " = radians(" << n.amount.glsl() << " * " << p << ".x);" << lineComment(n)
                 << " bend\n";
          f.code << "  vec3 " << q << " = vec3(cos(" << a << ") * " << p << ".x - sin(" << a << ") * " << p
                 << ".z, " << p << ".y, sin(" << a << ") * " << p << ".x + cos(" << a << ") * " << p << ".z);\n";
        }
        std::string c = node(*n.children[0], q, f, mat, mine);
        if (mat && !isIdentifier(c)) c = keep(f, c);
        const std::string r = var(f, "r"), d = var(f, "d");
        const std::string cylinder = "sdBox2(vec2(" + r + " - " + glslFloat(n.deform_radius) + ", abs(" + p + ".y - " +
                                     glslFloat((b.lo.y + b.hi.y) / 2) + ") - " + glslFloat((b.hi.y - b.lo.y) / 2) + "))";
        f.code << "  float " << r << " = length(" << p << ".xz);\n";
        if (n.deform_boxed) {
          // passes/deform.h: only near its box, the box's distance too outside.
          const Aabb region = n.bounds.grow(deformMargin(n));
          const glm::dvec3 centre = n.bounds.center(), half = n.bounds.halfSize();
          f.code << "  float " << d << " = " << r << " <= " << glslFloat(deformReach(n)) << " && all(lessThanEqual(abs("
                 << p << ".xz - vec2(" << glslFloat(region.center().x) << ", " << glslFloat(region.center().z)
                 << ")), vec2(" << glslFloat(region.halfSize().x) << ", " << glslFloat(region.halfSize().z) << "))) ? " << (mat ? c + ".x" : c)
                 << " * " << glslFloat(1 / n.deform_lipschitz) << " : max(" << cylinder << ", length(max(abs(" << p
                 << " - " << vec3Literal(centre) << ") - " << vec3Literal(half) << ", 0.0)));\n";
        } else {
          f.code << "  float " << d << " = " << r << " <= " << glslFloat(deformReach(n)) << " ? "
                 << (mat ? c + ".x" : c) << " * " << glslFloat(1 / n.deform_lipschitz) << " : " << cylinder << ";\n";
        }
        return mat ? "vec2(" + d + ", " + c + ".y)" : d;
      }
      case ir::NodeKind::Displace: {
        // The octaves unrolled: a loop would count against lavapipe's cap at
        // every march step.
        if (helper_names_.insert("noise").second) helpers_ << "\n" << embeddedSource("kernel/noise.glsl") << "\n";
        std::string c = node(*n.children[0], p, f, mat, mine);
        if (mat && !isIdentifier(c)) c = keep(f, c);
        const std::string q = var(f, "p"), d = var(f, "d");
        f.code << "  vec3 " << q << " = " << p << " * " << n.vec.x.glsl() << ";" << lineComment(n) << " displace\n";
        double weight = 0;
        std::string sum;
        for (int i = 0; i < n.count.x; ++i) {
          const double amplitude = std::ldexp(1.0, -i);
          weight += amplitude;
          sum += (i ? " + " : "") + (i ? glslFloat(amplitude) + " * " : std::string()) + "sdGradientNoise(" +
                 (i ? glslFloat(std::ldexp(1.0, i)) + " * " : std::string()) + q + ")";
        }
        f.code << "  float " << d << " = (" << (mat ? c + ".x" : c) << " + " << n.amount.glsl() << " * ("
               << sum << ")" << (n.count.x > 1 ? " * " + glslFloat(1 / weight) : std::string()) << ") * "
               << glslFloat(1 / n.deform_lipschitz) << ";\n";
        if (n.bounds.finite()) {
          // As the evaluator: outside its box, no less than the box's distance.
          needHelper("sdBound", kAabbHelper);
          const std::string b = var(f, "b");
          f.code << "  float " << b << " = sdBound(" << p << ", " << vec3Literal(n.bounds.center()) << ", "
                 << vec3Literal(n.bounds.halfSize()) << ");\n";
          f.code << "  " << d << " = " << b << " > 0.0 ? max(" << d << ", " << b << ") : " << d << ";\n";
        }
        return mat ? "vec2(" + d + ", " + c + ".y)" : d;
      }
      case ir::NodeKind::RepeatPolar: {
        if (n.count.x == 1) return node(*n.children[0], p, f, mat, mine);
        // The sector whose copy is nearest in angle and those polarSectors()
        // adds (passes.h), each turned back onto sector 0, the child
        // evaluated through one function.
        const ir::Node& c = *n.children[0];
        const PolarSectors s = polarSectors(n);
        const std::string w = glslFloat(2 * M_PI / n.count.x), i = var(f, "i");
        std::string angle = "atan(" + p + ".z, " + p + ".x)";
        if (s.centre != 0) {
          // The angle from the child's centre, wrapped into [-pi, pi].
          const std::string u = var(f, "u");
          f.code << "  float " << u << " = " << angle << " - " << glslFloat(s.centre) << ";\n";
          angle = "(" + u + " - 6.2831853 * round(" + u + " * 0.15915494))";
        }
        f.code << "  float " << i << " = round(" << angle << " / " << w << ");" << lineComment(n) << " repeat_polar\n";
        const std::string label = c.definition.empty() ? "sector" : c.definition;
        const std::string acc = var(f, "d");
        for (int d = s.first; d <= s.last; ++d) {
          const std::string a = var(f, "a"), q = var(f, "p");
          f.code << "  float " << a << " = (" << i << (d < 0 ? " - " : d > 0 ? " + " : "")
                 << (d != 0 ? glslFloat(std::abs(d)) : std::string()) << ") * " << w << ";\n";
          f.code << "  vec3 " << q << " = vec3(cos(" << a << ") * " << p << ".x + sin(" << a << ") * " << p << ".z, "
                 << p << ".y, cos(" << a << ") * " << p << ".z - sin(" << a << ") * " << p << ".x);\n";
          const std::string e = callFunction(c, q, f, mat, mine, label);
          if (d == s.first) {
            f.code << "  " << (mat ? "vec2 " : "float ") << acc << " = " << e << ";\n";
          } else {
            const std::string r = var(f, "r");
            f.code << "  " << (mat ? "vec2 " : "float ") << r << " = " << e << ";\n";
            if (mat) f.code << "  if (" << r << ".x < " << acc << ".x) " << acc << " = " << r << ";\n";
            else f.code << "  " << acc << " = min(" << acc << ", " << r << ");\n";
          }
        }
        return acc;
      }
      case ir::NodeKind::Revolve: {
        const std::string q = var(f, "p");
        f.code << "  vec3 " << q << " = vec3(length(" << p << ".xz) - " << n.amount.glsl() << ", " << p
               << ".y, 0.0);" << lineComment(n) << " revolve\n";
        // A lathe's polygon without its edges on the axis (a polygon has one
        // material, so the uniform-material path above takes it when `mat`).
        if (n.lathe && !mat) return polygon(*n.children[0], q, f, -n.amount.value);
        return node(*n.children[0], q, f, mat, mine);
      }
      default: return domain(n, p, f, mat, mine, cut);
    }
  }


  // ---- instances: data, a hierarchy and one loop (docs/design/large_scenes.md) ----

  void pushVec4(float x, float y, float z, float w) {
    data_.push_back(x);
    data_.push_back(y);
    data_.push_back(z);
    data_.push_back(w);
  }

  // The unit quaternion of a placement that only rotates (scale 1, a proper
  // rotation to within float64 rounding), else none.
  static std::optional<glm::dquat> rotorOf(const ir::InstanceTransform& t) {
    if (t.scale != 1 || glm::determinant(t.linear) <= 0) return std::nullopt;
    const glm::dquat r = glm::normalize(glm::quat_cast(t.linear));
    const glm::dmat3 back = glm::mat3_cast(r);
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k)
        if (std::fabs(back[c][k] - t.linear[c][k]) > 1e-12) return std::nullopt;
    return r;
  }

  // Appends the set's hierarchy and records to the scene data, once per node.
  const InstanceLayout& instanceLayout(const ir::Node& n) {
    auto it = instance_layouts_.find(&n);
    if (it != instance_layouts_.end()) return it->second;
    const ir::InstanceSet& set = *n.instances;
    InstanceLayout l;
    l.id = static_cast<int>(instance_layouts_.size());
    l.affine = !set.transforms.empty();
    l.mixed = n.children.size() > 1;
    // In the placement's free slot, the template index costs no vec4: a
    // kit-bash's records of 4 parameters take 5 vec4, not 6 (kit-bash 1,000
    // 401 -> 387 ms a sample; docs/design/large_scenes.md, "Cost per part").
    l.templ_in_placement = l.mixed && l.affine;
    l.param_in_w = !l.affine && !l.mixed && set.param_count == 1 &&
                   std::all_of(set.instances.begin(), set.instances.end(),
                               [](const ir::Instance& i) { return i.material < 0; });
    // Each shared transform's quaternion, computed once (none where it does more than rotate).
    std::vector<std::optional<glm::dquat>> rotors;
    if (l.affine)
      for (const ir::InstanceTransform& t : set.transforms) rotors.push_back(rotorOf(t));
    const bool packable = n.children.size() <= 256;
    l.rotor = l.affine && std::all_of(set.instances.begin(), set.instances.end(), [&](const ir::Instance& i) {
      return (i.material < 0 || (packable && i.material < 65535)) &&
             (i.transform < 0 || rotors[i.transform].has_value());
    });
    l.rotor_material = l.rotor && std::any_of(set.instances.begin(), set.instances.end(),
                                              [](const ir::Instance& i) { return i.material >= 0; });
    l.param_vec4 = l.param_in_w ? 0 : (set.param_count + (l.mixed && !l.templ_in_placement ? 1 : 0) + 3) / 4;
    l.stride = (l.rotor ? 2 : l.affine ? 4 : 1) + l.param_vec4;
    // Indices are stored as float values: exact below 2^24.
    l.nodes = data_.size() / 4;
    for (const ir::BvhNode& b : set.nodes) {
      pushVec4(float(b.box.lo.x), float(b.box.lo.y), float(b.box.lo.z), float(b.first));
      pushVec4(float(b.box.hi.x), float(b.box.hi.y), float(b.box.hi.z), float(b.count));
    }
    l.records = data_.size() / 4;
    data_.reserve(data_.size() + set.size() * l.stride * 4);
    for (size_t i = 0; i < set.size(); ++i) {
      const ir::Instance& inst = set.instances[i];
      if (l.rotor) {
        const glm::dquat r = inst.transform >= 0 ? *rotors[inst.transform] : glm::dquat(1, 0, 0, 0);
        pushVec4(float(r.x), float(r.y), float(r.z), float(r.w));
        const float w = l.rotor_material ? float(inst.templ + 256 * (inst.material + 1)) : l.mixed ? float(inst.templ) : 0;
        pushVec4(float(inst.offset.x), float(inst.offset.y), float(inst.offset.z), w);
      } else if (l.affine) {
        glm::dmat3 m(1.0);
        double scale = 1;
        if (inst.transform >= 0) {
          m = set.transforms[inst.transform].linear;
          scale = set.transforms[inst.transform].scale;
        }
        for (int row = 0; row < 3; ++row)
          pushVec4(float(m[0][row]), float(m[1][row]), float(m[2][row]), float(inst.offset[row]));
        pushVec4(float(scale), float(inst.material), l.templ_in_placement ? float(inst.templ) : 0, 0);
      } else {
        pushVec4(float(inst.offset.x), float(inst.offset.y), float(inst.offset.z),
                 l.param_in_w ? float(set.paramsOf(i)[0]) : float(inst.material));
      }
      for (int v = 0; v < l.param_vec4; ++v) {
        float c[4] = {0, 0, 0, 0};
        for (int j = 0; j < 4 && v * 4 + j < set.param_count; ++j) c[j] = float(set.paramsOf(i)[v * 4 + j]);
        if (l.mixed && !l.templ_in_placement && set.param_count / 4 == v) c[set.param_count % 4] = float(inst.templ);
        pushVec4(c[0], c[1], c[2], c[3]);
      }
    }
    if (!set.grid.empty()) {
      // Header (lo, cell), (dims, margin); per cell (first, count, reach, 0);
      // the lists' instance indices, four per vec4.
      const ir::InstanceGrid& grid = set.grid;
      l.grid = true;
      l.grid_header = data_.size() / 4;
      pushVec4(float(grid.lo.x), float(grid.lo.y), float(grid.lo.z), float(grid.cell));
      pushVec4(float(grid.dims.x), float(grid.dims.y), float(grid.dims.z), float(grid.margin));
      l.grid_cells = data_.size() / 4;
      l.slot_vec4 = packed_slots_ ? kPackedSlotVec4 : ir::kGridListMax;
      l.grid_slots = options_.with_kernel && &n == ray_skip_set_ && sphereCloud(n) &&
                     data_.size() * 4 + grid.cells() * size_t(1 + l.slot_vec4) * 16 <= kMaxSlotDataBytes;
      data_.reserve(data_.size() + grid.cells() * 4 + grid.entries.size() + 4);
      // A split cell's x is its first sub-cell's index; fixed slots are at
      // cell index x kGridListMax, which the lookup computes.
      for (size_t c = 0; c < grid.cells(); ++c)
        pushVec4(float(l.grid_slots && grid.count[c] != ir::kGridSplit ? c * ir::kGridListMax : grid.first[c]),
                 float(grid.count[c]), float(grid.reach[c]), 0);
      l.grid_entries = data_.size() / 4;
      if (l.grid_slots) {
        l.grid_records = true;
        const int floats = packed_slots_ ? 3 : 4;
        const float far[4] = {1e15f, 1e15f, 1e15f, -1};
        data_.reserve(data_.size() + grid.cells() * l.slot_vec4 * 4);
        for (size_t c = 0; c < grid.cells(); ++c) {
          const int count = std::max(grid.count[c], 0);
          for (int k = 0; k < ir::kGridListMax; ++k) {
            // An empty, crowded or split cell's slots: far from everything,
            // never the minimum distance or hit (and no list entry to read).
            if (count == 0) {
              data_.insert(data_.end(), far, far + floats);
              continue;
            }
            const size_t r = (l.records + grid.entries[grid.first[c] + std::min(k, count - 1)]) * 4;
            for (int j = 0; j < floats; ++j) data_.push_back(data_[r + j]);
          }
        }
        return instance_layouts_.emplace(&n, l).first->second;
      }
      // One-vec4 records (no rotation, no parameters: point clouds) are copied
      // into the lists, which saves a dependent load per listed instance; so
      // are a blend grid's records of any size, its lists being evaluated
      // whole (1,000 blended spheres 230 -> 182 ms a sample, kit-bash 460 ->
      // 431: docs/design/large_scenes.md, "Cost per part").
      l.grid_records = (l.stride == 1 || grid.blend) &&
                       grid.entries.size() * 16 * size_t(l.stride) <= kMaxCopiedRecordBytes;
      if (l.grid_records) {
        for (std::uint32_t e : grid.entries) {
          const size_t r = (l.records + size_t(e) * l.stride) * 4;
          for (int v = 0; v < l.stride; ++v)
            pushVec4(data_[r + 4 * v], data_[r + 4 * v + 1], data_[r + 4 * v + 2], data_[r + 4 * v + 3]);
        }
      } else {
        for (std::uint32_t e : grid.entries) data_.push_back(float(e));
        while (data_.size() % 4 != 0) data_.push_back(0);
      }
    }
    return instance_layouts_.emplace(&n, l).first->second;
  }

  static bool gridHasSplitCells(const ir::InstanceGrid& grid) {
    return std::find(grid.count.begin(), grid.count.end(), ir::kGridSplit) != grid.count.end();
  }

  // Slot k's packed centre: floats 3k..3k+2 of its cell's 24, read from the
  // cell's kPackedSlotVec4 vec4 a0.. (a centre may straddle two of them).
  static std::string slotCentre(int k) {
    const int j = 3 * k, first = j / 4, last = (j + 2) / 4;
    const std::string xyzw = "xyzw";
    if (first == last) return "a" + std::to_string(first) + "." + xyzw.substr(j % 4, 3);
    return "vec3(a" + std::to_string(first) + "." + xyzw.substr(j % 4) + ", a" + std::to_string(last) + "." +
           xyzw.substr(0, (j + 3) % 4) + ")";
  }

  // The fixed slots of cell ci into s0..s7 (declared first when `declare`).
  static std::string slotLoads(const InstanceLayout& l, const std::string& indent, bool declare) {
    std::ostringstream out;
    if (declare) out << indent << "vec3 s0, s1, s2, s3, s4, s5, s6, s7;\n";
    const std::string cell = std::to_string(l.grid_entries) + " + ci * " + std::to_string(l.slot_vec4) + " + ";
    if (l.slot_vec4 != kPackedSlotVec4) {
      for (int k = 0; k < ir::kGridListMax; ++k) out << indent << "s" << k << " = sd_data[" << cell << k << "].xyz;\n";
      return out.str();
    }
    out << indent << "{\n";
    for (int j = 0; j < kPackedSlotVec4; ++j) out << indent << "  vec4 a" << j << " = sd_data[" << cell << j << "];\n";
    for (int k = 0; k < ir::kGridListMax; ++k) out << indent << "  s" << k << " = " << slotCentre(k) << ";\n";
    out << indent << "}\n";
    return out.str();
  }

  // A split cell (ir::kGridSplit: too crowded for one list) hands p to its
  // octant's sub-cell, half the size: ci, q, size and cell (and the fixed
  // slots) become the sub-cell's. q * 2 - o is exact in float.
  std::string splitCellLookup(const InstanceLayout& l, bool slots, bool sized, bool again = false) const {
    std::ostringstream out;
    if (sized && !again) out << "  float size = g0.w;\n";
    sized = sized || again;
    out << "  if (cell.y < -1.5) {  // split: the octant's sub-cell\n";
    out << "    ivec3 o = ivec3(greaterThanEqual(q, vec3(0.5)));\n";
    out << "    ci = int(cell.x) + o.x + 2 * o.y + 4 * o.z;\n";
    out << "    q = q * 2.0 - vec3(o);\n";
    if (sized) out << "    size *= 0.5;\n";
    out << "    cell = sd_data[" << l.grid_cells << " + ci];\n";
    if (slots) out << "    first = ci * " << ir::kGridListMax << ";\n" << slotLoads(l, "    ", false);
    out << "  }\n";
    return out.str();
  }

  // The grid's lookup (ir::InstanceGrid): outside its box the margin bound,
  // in a split cell its octant's sub-cell, in a crowded (sub-)cell (or with
  // fewer visits than the list) the hierarchy, else the cell's list and its
  // reach.
  void gridFunction(const ir::Node& n, const InstanceLayout& l, bool mat, const std::string& name,
                    const std::string& one, const std::string& tree) {
    const std::string gh = std::to_string(l.grid_header), gc = std::to_string(l.grid_cells),
                      ge = std::to_string(l.grid_entries), ib = std::to_string(l.records);
    const std::string visits = options_.with_kernel ? "int(frame.traversal_visits)" : std::to_string(kSceneOnlyVisits);
    const ir::InstanceGrid& grid = n.instances->grid;
    Function g;
    g.code << lineDirective(n);
    g.code << "// Grid of " << grid.dims.x << "x" << grid.dims.y << "x" << grid.dims.z << " cells at sd_data[" << gh
           << "]: a lookup and a list of "
           << (grid.blend ? std::string("the members that can change the blend in the cell")
                          : "at most " + std::to_string(ir::kGridListMax))
           << " (docs/design/large_scenes.md).\n";
    g.code << (mat ? "vec2 " : "float ") << name << "(vec3 p" << (mat ? ", float inherited" : "") << ") {\n";
    g.code << "  vec4 g0 = sd_data[" << gh << "], g1 = sd_data[" << gh << " + 1];\n";
    g.code << "  vec3 o = max(max(g0.xyz - p, p - (g0.xyz + g1.xyz * g0.w)), 0.0);\n";
    g.code << "  // Outside the grid's box: every instance is at least the margin farther"
           << (grid.blend ? " (less 1.25 k: a blend's bound)" : "") << ".\n";
    g.code << "  if (o != vec3(0.0)) return " << (mat ? "vec2(length(o) + g1.w, inherited)" : "length(o) + g1.w")
           << ";\n";
    g.code << "  ivec3 dims = ivec3(g1.xyz);\n  vec3 f = (p - g0.xyz) / g0.w;\n";
    g.code << "  ivec3 c = clamp(ivec3(floor(f)), ivec3(0), dims - 1);\n";
    // The root set's lookup also bounds the first hit along g_ray_dir (the
    // same argument along the ray, instance_grid.cpp): to the cell's exit plus
    // the reach, or to a listed instance, exactly for a sphere.
    const bool skip = !mat && ray_skip_set_ == &n;
    const std::string ray_hit = skip ? rayHitFunction(n, l, one) : "";
    if (!ray_hit.empty()) sphereNormalFunction(n, l, visits);
    const bool unrolled = l.grid_slots && !ray_hit.empty();
    const bool split = gridHasSplitCells(grid);
    const std::string size = split ? "size" : "g0.w";
    g.code << "  int ci = c.x + dims.x * (c.y + dims.y * c.z);\n";
    if (unrolled) {
      // Fixed slots start at ci * slot_vec4: computed, not read, and loaded
      // before the cell is tested, so their loads wait neither for the cell's
      // nor for a mask that depends on it (a crowded or split cell's slots
      // hold far dummies, loaded and unused). Slot k of cell ci is numbered
      // first + k (g_ray_met_slot).
      g.code << "  int first = ci * " << ir::kGridListMax << ";\n";
      g.code << slotLoads(l, "  ", true);
    }
    g.code << "  vec4 cell = sd_data[" << gc << " + ci];\n";
    g.code << "  vec3 q = f - vec3(c);\n";
    g.code << countEvent(kEventLookups);
    if (split) {
      g.code << splitCellLookup(l, unrolled, true);
      // A blend grid's octants may be split again: the same step per level.
      for (int level = 1; level < grid.splits; ++level) g.code << splitCellLookup(l, unrolled, false, true);
    }
    g.code << "  int count = int(cell.y);\n";
    if (grid.blend) {
      blendList(n, l, mat, one, tree, visits, size, g);
      return;
    }
    // Fixed slots take no loop iterations: only a crowded cell needs the hierarchy.
    g.code << "  if (count < 0" << (unrolled ? std::string() : " || count > " + visits) << ") return " << tree
           << "(p" << (mat ? ", inherited" : "") << ");\n";
    g.code << "  // Unlisted instances are at least the reach plus the way to the cell's faces away.\n";
    g.code << "  float face = min(min(min(q.x, q.y), q.z), min(min(1.0 - q.x, 1.0 - q.y), 1.0 - q.z));\n";
    g.code << "  " << (mat ? "vec2 best = vec2(cell.z + " + size + " * max(face, 0.0), inherited);"
                            : "float best = cell.z + " + size + " * max(face, 0.0);")
           << "\n";
    if (!unrolled) g.code << "  int first = int(cell.x);\n";
    if (skip) {
      g.code << "  vec3 rd = g_ray_dir;\n";
      g.code << "  vec3 to_exit = mix(q, 1.0 - q, greaterThan(rd, vec3(0.0))) / max(abs(rd), 1e-30);\n";
      g.code << "  float skip = cell.z + " << size << " * max(min(min(to_exit.x, to_exit.y), to_exit.z), 0.0);\n";
    }
    if (unrolled) {
      // kGridListMax fixed slots in straight-line code (padded lists). One
      // radius: the nearest centre's squared distance, one square root after
      // (sqrt is monotonic and correctly rounded: the same value as the
      // minimum of the lengths); the ray hit shares q.q.
      g.code << "  float r = " << sphereCloudRadius(n) << ", qq_min = 1e30;\n";
      // The listed spheres' first hit th_min (its slot the first that attains
      // it), then the skip: the same values as testing each hit against the
      // skip in turn. th_min is a hit of the ray wherever it lies (a shadow
      // ray's any-hit test in march()).
      g.code << "  float th_min = 1e30;\n  int slot = 0;\n";
      for (int k = 0; k < ir::kGridListMax; ++k) {
        g.code << "  {\n" << countEvent(kEventEntries, "  ");
        g.code << "    vec3 q = p + s" << k << ";\n";
        g.code << "    float qq = dot(q, q), b = dot(q, rd), c = qq - r * r, h = b * b - c;\n";
        g.code << "    qq_min = min(qq_min, qq);\n";
        g.code << "    float th = c <= 0.0 ? 0.0 : (b >= 0.0 || h < 0.0 ? 1e30 : c / (sqrt(h) - b));\n";
        g.code << "    if (th < th_min) {\n      th_min = th;\n      slot = " << k << ";\n    }\n  }\n";
      }
      g.code << "  if (th_min < skip) {\n    skip = th_min;\n    g_ray_met = th_min > 0.0;\n"
                "    g_ray_met_slot = first + slot;\n  }\n";
      g.code << "  g_ray_any = th_min;\n";
      g.code << "  best = min(best, sqrt(qq_min) - r);\n";
      g.code << "  g_ray_skip = skip;\n  return best;\n}\n";
      functions_ << g.code.str();
      return;
    }
    if (options_.with_kernel) {
      g.code << "  for (int it = loopZero(); it < count; it++) {\n    g_loop_iterations++;\n";
    } else {
      g.code << "  for (int it = 0; it < count; it++) {\n";
    }
    g.code << countEvent(kEventEntries, "  ");
    g.code << "    int e = first + it;\n";
    g.code << "    int rec = " << listedRecord(l) << ";\n";
    if (mat) {
      g.code << "    vec2 r = " << one << "(p, rec, inherited);\n    if (r.x < best.x) best = r;\n";
    } else if (skip) {
      g.code << "    float di = " << one << "(p, rec);\n    best = min(best, di);\n";
      if (ray_hit.empty()) {
        g.code << "    skip = min(skip, di);\n";
      } else {
        g.code << "    float th = " << ray_hit << "(p, rd, rec);\n";
        g.code << "    if (th < skip) {\n      skip = th;\n      g_ray_met = th > 0.0;\n    }\n";
      }
    } else {
      g.code << "    best = min(best, " << one << "(p, rec));\n";
    }
    g.code << "  }\n";
    if (skip) g.code << "  g_ray_skip = skip;\n";
    g.code << "  return best;\n}\n";
    functions_ << g.code.str();
  }

  // A blend grid's cell (passes/blend_grid.cpp): the list's values, then
  // their smooth minimum nearest first over those within k of the nearest
  // (each pass picks the next by value, then by place in the list), which is
  // the whole set's blend there. Only a driver that caps loops, with too few
  // visits left for the list, takes the hierarchy. The values are not kept
  // in an array: lavapipe turns an array indexed by the loop into a ladder of
  // branches per access, paid on every entry; where three or more lie within
  // k of the least (rare) each pass evaluates the list again instead.
  void blendList(const ir::Node& n, const InstanceLayout& l, bool mat, const std::string& one,
                 const std::string& tree, const std::string& visits, const std::string& size, Function& g) {
    g.code << "  // Far from every part: a bound to step on.\n";
    g.code << "  if (count == 0) {\n";
    g.code << "    float face = min(min(min(q.x, q.y), q.z), min(min(1.0 - q.x, 1.0 - q.y), 1.0 - q.z));\n";
    g.code << "    float far = cell.z + " << size << " * max(face, 0.0);\n";
    g.code << "    return " << (mat ? "vec2(far, inherited)" : "far") << ";\n  }\n";
    const std::string loop0 = options_.with_kernel ? "loopZero()" : "0";
    const std::string tick = options_.with_kernel ? "    g_loop_iterations++;\n" : "";
    // Only a driver that caps loops takes the hierarchy (its visits are never
    // fewer than the list's otherwise): the constant drops it from the others'.
    g.code << "  if (" << (options_.with_kernel ? "kDriverCapsLoops && " : "") << "count * (count + 2) > " << visits
           << ") return " << tree << "(p" << (mat ? ", inherited" : "") << ");\n";
    g.code << "  float k = " << n.smooth.glsl() << ";\n";
    g.code << "  int first = int(cell.x);\n";
    // The three least values as they come (the first of equals first): where
    // fewer than three lie within k of the least, the blend is known without
    // the passes below (the same blends in the same order).
    g.code << "  float m = 1e30, m2 = 1e30, m3 = 1e30;\n";
    if (mat) g.code << "  float mm = inherited;\n";
    g.code << "  for (int it = " << loop0 << "; it < count; it++) {\n" << tick;
    g.code << countEvent(kEventEntries, "  ");
    g.code << "    int e = first + it;\n";
    g.code << "    int rec = " << listedRecord(l) << ";\n";
    if (mat) {
      g.code << "    vec2 r = " << one << "(p, rec, inherited);\n    float x = r.x;\n";
    } else {
      g.code << "    float x = " << one << "(p, rec);\n";
    }
    g.code << "    if (x < m) {\n      m3 = m2;\n      m2 = m;\n      m = x;\n" << (mat ? "      mm = r.y;\n" : "")
           << "    } else if (x < m2) {\n      m3 = m2;\n      m2 = x;\n    } else {\n      m3 = min(m3, x);\n    }\n  }\n";
    g.code << "  if (m2 >= m + k) return " << (mat ? "vec2(m, mm)" : "m") << ";\n";
    g.code << "  if (m3 >= m + k) return " << (mat ? "vec2(sdSmoothMin(m, m2, k), mm)" : "sdSmoothMin(m, m2, k)")
           << ";\n";
    g.code << "  " << (mat ? "vec2 best = vec2(1e30, inherited);" : "float best = 1e30;") << "\n";
    g.code << "  float last = -1e30;\n  int last_j = -1;\n";
    g.code << "  for (int s = " << loop0 << "; s < count; s++) {\n" << tick;
    g.code << "    float nv = 1e30;\n    int nj = -1;\n" << (mat ? "    float nm = inherited;\n" : "");
    g.code << "    for (int j = " << loop0 << "; j < count; j++) {\n" << tick;
    g.code << "      int e = first + j;\n";
    g.code << "      int rec = " << listedRecord(l) << ";\n";
    if (mat) {
      g.code << "      vec2 r = " << one << "(p, rec, inherited);\n      float x = r.x;\n";
    } else {
      g.code << "      float x = " << one << "(p, rec);\n";
    }
    g.code << "      if ((x > last || (x == last && j > last_j)) && x < nv) {\n        nv = x;\n        nj = j;\n"
           << (mat ? "        nm = r.y;\n" : "") << "      }\n";
    g.code << "    }\n";
    g.code << "    if (nj < 0 || nv >= m + k) break;\n";
    if (mat) {
      g.code << "    best = vec2(sdSmoothMin(best.x, nv, k), nv < best.x ? nm : best.y);\n";
    } else {
      g.code << "    best = sdSmoothMin(best, nv, k);\n";
    }
    g.code << "    last = nv;\n    last_j = nj;\n  }\n  return best;\n}\n";
    functions_ << g.code.str();
  }

  // --count-event: the counter's globals; g_event_kind is set by the kernel
  // (-1: not counted, e.g. the AOV ray).
  void countEventDeclarations(std::ostream& out) const {
    int kind = 0, quantity = 0;
    if (!countEventFromName(options_.count_event, kind, quantity)) return;
    out << "\n// --count-event " << options_.count_event << ": counted per pixel into the iterations view's green.\n";
    out << "float g_events = 0.0;\nint g_event_kind = -1;\n";
    out << "void countEvent(int quantity) {\n";
    out << "  if (quantity == " << quantity << " && g_event_kind >= 0"
        << (kind >= 0 ? " && g_event_kind == " + std::to_string(kind) : std::string()) << ") g_events += 1.0;\n}\n";
  }
  // A call of countEvent(quantity) when counting (and a kernel is emitted), else "".
  std::string countEvent(int quantity, const std::string& indent = "") const {
    if (options_.count_event.empty() || !options_.with_kernel) return "";
    return indent + "  countEvent(" + std::to_string(quantity) + ");\n";
  }

  // The record of list entry e (in scope as `e`).
  std::string listedRecord(const InstanceLayout& l) const {
    const std::string ge = std::to_string(l.grid_entries);
    // Fixed slots read as records only with a material to read: unpacked.
    if (l.grid_records) return ge + " + e" + (l.stride > 1 ? " * " + std::to_string(l.stride) : "");
    return std::to_string(l.records) + " + int(sd_data[" + ge + " + (e >> 2)][e & 3]) * " +
           std::to_string(l.stride);
  }

  // The root grid's spheres (SDFC_HAS_SPHERE_NORMALS): the gradient at p is
  // the radial direction of the nearest listed sphere, one lookup instead of
  // the normal's 4 taps. False, having spent no loop iterations, where the
  // cell has no usable list; the kernel then takes the taps.
  void sphereNormalFunction(const ir::Node& n, const InstanceLayout& l, const std::string& visits) {
    has_sphere_normals_ = true;
    const std::string gh = std::to_string(l.grid_header), gc = std::to_string(l.grid_cells);
    Function g;
    g.code << "bool sdRootSphereNormal(vec3 p, out vec3 normal, out float field) {\n";
    if (l.grid_slots) {
      // The march ended on this sphere's analytic hit (the first hit, so no
      // sphere is nearer than its surface at p): its radial direction, the
      // same arithmetic as the slots below, with no lookup.
      has_sphere_hit_ = true;
      g.code << "  if (g_hit_sphere >= 0) {\n";
      if (l.slot_vec4 == kPackedSlotVec4) {
        // Its centre: floats j..j+2 of its cell's packed slots at vec4 v.
        g.code << "    int v = " << l.grid_entries << " + (g_hit_sphere / " << ir::kGridListMax << ") * "
               << kPackedSlotVec4 << ", j = 3 * (g_hit_sphere % " << ir::kGridListMax << ");\n";
        g.code << "    vec3 q_near = p + vec3(sd_data[v + j / 4][j % 4], sd_data[v + (j + 1) / 4][(j + 1) % 4],\n"
                  "                           sd_data[v + (j + 2) / 4][(j + 2) % 4]);\n";
      } else {
        g.code << "    vec3 q_near = p + sd_data[" << l.grid_entries << " + g_hit_sphere].xyz;\n";
      }
      g.code << "    field = sqrt(dot(q_near, q_near)) - " << sphereCloudRadius(n)
             << ";\n    float len = length(q_near);\n"
             << "    normal = len > 0.0 ? q_near / len : vec3(0.0, 1.0, 0.0);\n    return true;\n  }\n";
    }
    g.code << "  vec4 g0 = sd_data[" << gh << "], g1 = sd_data[" << gh << " + 1];\n";
    g.code << "  if (any(lessThan(p, g0.xyz)) || any(greaterThan(p, g0.xyz + g1.xyz * g0.w))) return false;\n";
    g.code << "  ivec3 dims = ivec3(g1.xyz);\n  vec3 f = (p - g0.xyz) / g0.w;\n";
    g.code << "  ivec3 c = clamp(ivec3(floor(f)), ivec3(0), dims - 1);\n";
    g.code << "  int ci = c.x + dims.x * (c.y + dims.y * c.z);\n";
    g.code << "  vec4 cell = sd_data[" << gc << " + ci];\n";
    g.code << countEvent(kEventLookups);
    if (gridHasSplitCells(n.instances->grid)) {
      g.code << "  vec3 q = f - vec3(c);\n";
      g.code << splitCellLookup(l, false, false);
    }
    if (l.grid_slots) {
      g.code << "  int count = int(cell.y), first = ci * " << ir::kGridListMax << ";\n";
    } else {
      g.code << "  int count = int(cell.y), first = int(cell.x);\n";
    }
    if (l.grid_slots) {
      // A crowded cell: one nearest-first traversal for the nearest sphere
      // (instead of 4 taps and the material, each walking the hierarchy).
      g.code << "  if (count < 0) return " << sphereNearestFunction(n, l) << "(p, normal, field);\n";
      g.code << "  if (count == 0) return false;\n";
    } else {
      g.code << "  if (count <= 0 || count > " << visits << ") return false;\n";
    }
    g.code << "  float r = " << sphereCloudRadius(n) << ";\n";
    g.code << "  field = 1e30;\n  vec3 q_near = vec3(0.0, 1.0, 0.0);\n";
    if (l.grid_slots) {
      // kGridListMax fixed slots in straight-line code (padded lists); the
      // nearest by squared distance, one square root after.
      g.code << "  float qq_min = 1e30;\n";
      g.code << slotLoads(l, "  ", true);
      for (int k = 0; k < ir::kGridListMax; ++k)
        g.code << "  {\n" << countEvent(kEventEntries, "  ") << "    vec3 q = p + s" << k
               << ";\n    float qq = dot(q, q);\n"
               << "    if (qq < qq_min) {\n      qq_min = qq;\n      q_near = q;\n    }\n  }\n";
      g.code << "  field = sqrt(qq_min) - r;\n";
    } else {
      g.code << "  for (int it = loopZero(); it < count; it++) {\n    g_loop_iterations++;\n";
      g.code << countEvent(kEventEntries, "  ");
      g.code << "    int e = first + it;\n    vec3 q = p + sd_data[" << listedRecord(l) << "].xyz;\n";
      g.code << "    float d = length(q) - r;\n";
      g.code << "    if (d < field) {\n      field = d;\n      q_near = q;\n    }\n  }\n";
    }
    g.code << "  float len = length(q_near);\n";
    g.code << "  normal = len > 0.0 ? q_near / len : vec3(0.0, 1.0, 0.0);\n  return true;\n}\n";
    functions_ << g.code.str();
  }

  // One sphere of constant radius placed by offsets (a point cloud).
  static bool sphereCloud(const ir::Node& n) { return ir::isSphereCloud(*n.instances, *n.children[0]); }

  // A sphere cloud's constant radius as a GLSL literal.
  static std::string sphereCloudRadius(const ir::Node& n) { return glslFloat(n.children[0]->args[0].value); }

  // The sphere cloud's nearest sphere to p through the hierarchy, nearest
  // first: a sphere of radius r boxed by B has distance >= dist(p, B) - r
  // (also inside it), so nodes no nearer than that are skipped and the least
  // distance, negative inside, is exact. Within the i = 0 iteration of the
  // normal loop and at most frame.traversal_visits visits, so the taps are not
  // taken after it (the loop cap argument): out of visits it answers with
  // the nearest found so far, or the degenerate field's (0, 1, 0).
  std::string sphereNearestFunction(const ir::Node& n, const InstanceLayout& l) {
    const std::string name = "sdRootSphereNearest";
    if (!helper_names_.insert(name).second) return name;
    needHelper("sdBoxDistance", kBoxDistanceHelper);
    const std::string nb = std::to_string(l.nodes), ib = std::to_string(l.records);
    const int stack = n.instances->depth + 1;
    auto box = [&](const std::string& i) {
      return "sdBoxDistance(p, sd_data[" + nb + " + 2 * " + i + "].xyz, sd_data[" + nb + " + 2 * " + i + " + 1].xyz)";
    };
    Function g;
    g.code << "bool " << name << "(vec3 p, out vec3 normal, out float field) {\n";
    g.code << "  float r = " << sphereCloudRadius(n) << ";\n";
    g.code << "  field = 1e30;\n  vec3 q_near = vec3(0.0);\n";
    g.code << "  int sn[" << stack << "];\n  float sd[" << stack << "];\n";
    g.code << "  sn[0] = 0;\n  sd[0] = " << box("0") << ";\n  int sp = 1;\n";
    g.code << "  for (int it = loopZero(); it < int(frame.traversal_visits) && sp > 0; it++) {\n";
    g.code << "    g_loop_iterations++;\n" << countEvent(kEventVisits, "  ");
    g.code << "    sp--;\n    if (sd[sp] - r >= field) continue;\n    int ni = sn[sp];\n";
    g.code << "    int first = int(sd_data[" << nb << " + 2 * ni].w), count = int(sd_data[" << nb << " + 2 * ni + 1].w);\n";
    g.code << "    if (count == 0) {\n      int lc = ni + 1, rc = first;\n";
    g.code << "      float dl = " << box("lc") << ", dr = " << box("rc") << ";\n";
    g.code << "      bool left_near = dl <= dr;\n";
    g.code << "      // The far child first, so the near one is visited next.\n";
    g.code << "      if (max(dl, dr) - r < field) {\n        sn[sp] = left_near ? rc : lc;\n"
              "        sd[sp] = max(dl, dr);\n        sp++;\n      }\n";
    g.code << "      if (min(dl, dr) - r < field) {\n        sn[sp] = left_near ? lc : rc;\n"
              "        sd[sp] = min(dl, dr);\n        sp++;\n      }\n";
    g.code << "    } else {\n";
    for (int k = 0; k < int(ir::kBvhLeafSize); ++k) {
      g.code << "      if (" << k << " < count) {\n";
      g.code << "        vec3 q = p + sd_data[" << ib << " + first + " << k << "].xyz;\n";
      g.code << "        float d = length(q) - r;\n";
      g.code << "        if (d < field) {\n          field = d;\n          q_near = q;\n        }\n      }\n";
    }
    g.code << "    }\n  }\n";
    g.code << "  float len = length(q_near);\n";
    g.code << "  normal = len > 0.0 ? q_near / len : vec3(0.0, 1.0, 0.0);\n  return true;\n}\n";
    functions_ << g.code.str();
    return name;
  }

  // Where the ray p + t rd (|rd| = 1) first meets the sphere at record `rec`
  // (0 inside, 1e30 if it misses), for sets of one constant sphere placed by
  // offsets; else "" and the caller bounds the hit by the distance.
  std::string rayHitFunction(const ir::Node& n, const InstanceLayout& l, const std::string& one) {
    if (!sphereCloud(n)) return "";
    const std::string name = one + "_ray";
    if (!helper_names_.insert(name).second) return name;
    Function g;
    g.code << "float " << name << "(vec3 p, vec3 rd, int rec) {\n";
    g.code << "  vec3 q = p + sd_data[rec].xyz;\n";
    g.code << "  float r = " << sphereCloudRadius(n) << ";\n";
    g.code << "  float b = dot(q, rd), c = dot(q, q) - r * r, h = b * b - c;\n";
    g.code << "  if (c <= 0.0) return 0.0;\n  if (b >= 0.0 || h < 0.0) return 1e30;\n";
    g.code << "  // The near root c / (-b + sqrt(h)): no cancellation (b < 0).\n";
    g.code << "  return c / (sqrt(h) - b);\n}\n";
    functions_ << g.code.str();
    return name;
  }

  // One instance at record `rec`: its placement, then the template.
  std::string instanceFunction(const ir::Node& n, const InstanceLayout& l, bool mat) {
    const std::string name = (mat ? "sdmi" : "sdi") + std::to_string(l.id) + "_one";
    if (!helper_names_.insert(name).second) return name;
    const ir::InstanceSet& set = *n.instances;
    Function g;
    g.code << (mat ? "vec2 " : "float ") << name << "(vec3 p, int rec" << (mat ? ", float inherited" : "")
           << ") {\n";
    std::string material = "sd_data[rec].w";
    std::string scale;
    if (l.rotor) {
      // q = r p r* + offset for the unit quaternion r = (r0.xyz, r0.w).
      g.code << "  vec4 r0 = sd_data[rec], r1 = sd_data[rec + 1];\n";
      g.code << "  vec3 c = 2.0 * cross(r0.xyz, p);\n";
      g.code << "  vec3 q = p + r0.w * c + cross(r0.xyz, c) + r1.xyz;\n";
      if (l.rotor_material) g.code << "  int w = int(r1.w);  // template + 256 (material + 1)\n";
    } else if (l.affine) {
      g.code << "  vec4 r0 = sd_data[rec], r1 = sd_data[rec + 1], r2 = sd_data[rec + 2], e = sd_data[rec + 3];\n";
      g.code << "  vec3 q = vec3(dot(r0.xyz, p) + r0.w, dot(r1.xyz, p) + r1.w, dot(r2.xyz, p) + r2.w);\n";
      material = "e.y";
      scale = "e.x";
    } else if (l.param_in_w) {
      g.code << "  vec4 r0 = sd_data[rec];\n  vec3 q = p + r0.xyz;\n";
    } else {
      g.code << "  vec3 q = p + sd_data[rec].xyz;\n";
    }
    if (mat) {
      if (l.rotor_material)
        g.code << "  float m = w >= 256 ? float((w >> 8) - 1) : inherited;\n";
      else if (l.param_in_w || l.rotor)
        g.code << "  float m = inherited;\n";
      else
        g.code << "  float m = " << material << " >= 0.0 ? " << material << " : inherited;\n";
    }
    const int base = l.rotor ? 2 : l.affine ? 4 : 1;
    for (int v = 0; v < l.param_vec4; ++v) g.code << "  vec4 a" << v << " = sd_data[rec + " << base + v << "];\n";
    auto slot = [&l](int j) {
      return l.param_in_w ? std::string("r0.w") : "a" + std::to_string(j / 4) + "." + "xyzw"[j % 4];
    };
    // Template t's value at q: its primitive with this record's parameters,
    // or its code.
    auto value = [&](const ir::Node& templ) {
      if (!ir::takesParams(set, templ)) return node(templ, "q", g, mat, mat ? "m" : "-1.0");
      const PrimitiveInfo& info = primitiveInfo(templ.primitive);
      needPrimitive(info);
      std::string call = std::string(info.glsl_function) + "(q";
      int j = 0;
      for (const ParamSpec& spec : info.params) {
        if (spec.type == ParamType::Vector) {
          call += ", vec3(" + slot(j) + ", " + slot(j + 1) + ", " + slot(j + 2) + ")";
          j += 3;
        } else {
          call += ", " + slot(j++);
        }
      }
      call += ")";
      const std::string d = var(g, "d");
      g.code << "  float " << d << " = " << call << ";" << lineComment(templ) << " " << info.name << "\n";
      if (options_.count_evaluations && options_.with_kernel) g.code << "  g_loop_iterations++;\n";
      return mat ? "vec2(" + d + ", m)" : d;
    };
    std::string r;
    if (!l.mixed) {
      r = value(*n.children[0]);
    } else {
      // One branch per template: lanes in lockstep run the branches some lane
      // takes, and a branch no lane takes is skipped.
      r = var(g, "part");
      g.code << "  int t = "
             << (l.rotor_material ? std::string("w & 255")
                 : l.rotor        ? std::string("int(r1.w)")
                 : l.templ_in_placement ? std::string("int(e.z)")
                                        : "int(" + slot(set.param_count) + ")")
             << ";\n";
      g.code << "  " << (mat ? "vec2 " : "float ") << r << ";\n";
      for (size_t t = 0; t < n.children.size(); ++t) {
        g.code << "  " << (t == 0 ? "" : "} else ") << (t + 1 < n.children.size() ? "if (t == " + std::to_string(t) + ") " : "") << "{\n";
        const std::string v = value(*n.children[t]);
        g.code << "  " << r << " = " << v << ";\n";
      }
      g.code << "  }\n";
    }
    if (!scale.empty()) r = mat ? "vec2(" + r + ".x * " + scale + ", " + r + ".y)" : "(" + r + " * " + scale + ")";
    g.code << "  return " << r << ";\n}\n";
    functions_ << g.code.str();
    return name;
  }

  std::string instances(const ir::Node& n, const std::string& p, Function& f, bool mat,
                        const std::string& inherited) {
    const InstanceLayout& l = instanceLayout(n);
    const std::string name = (mat ? "sdmi" : "sdi") + std::to_string(l.id);
    // With a grid the hierarchy is its fallback, under its own name.
    const std::string tree = l.grid ? name + "_tree" : name;
    if (helper_names_.insert(name).second) {
      needHelper("sdBoxSignedDistance", kSignedBoxDistanceHelper);
      const bool smooth = !n.smooth.isConst() || n.smooth.value > 0;
      if (smooth) needHelper("smooth", kSmoothHelpers);
      const std::string one = instanceFunction(n, l, mat);
      const ir::InstanceSet& set = *n.instances;
      const int stack = set.depth + 1;
      const std::string nb = std::to_string(l.nodes), ib = std::to_string(l.records);
      const std::string best = mat ? "best.x" : "best";
      const std::string slack = smooth ? " + k" : "";
      Function g;
      g.code << lineDirective(n);
      g.code << "// " << set.size() << " instances (" << set.origin << ")" << lineComment(n)
             << ": hierarchy of " << set.nodes.size() << " nodes at sd_data[" << nb
             << "], records of " << l.stride << " vec4 at sd_data[" << ib << "].\n";
      g.code << "// Nearest first; a box no nearer than the best so far" << (smooth ? " + k" : "")
             << " is skipped.\n";
      g.code << (mat ? "vec2 " : "float ") << tree << "(vec3 p" << (mat ? ", float inherited" : "") << ") {\n";
      g.code << "  " << (mat ? "vec2 best = vec2(1e30, inherited);" : "float best = 1e30;") << "\n";
      if (smooth) g.code << "  float k = " << n.smooth.glsl() << ";\n";
      g.code << "  // Stack: node, its box distance, and the least box distance at or below.\n";
      g.code << "  int sn[" << stack << "];\n  float sd[" << stack << "], sm[" << stack << "];\n";
      g.code << "  vec4 a = sd_data[" << nb << "], b = sd_data[" << nb << " + 1];\n";
      g.code << "  sn[0] = 0;\n  sd[0] = sdBoxSignedDistance(p, a.xyz, b.xyz);\n  sm[0] = sd[0];\n  int sp = 1;\n";
      if (options_.with_kernel) {
        g.code << "  for (int it = loopZero(); it < int(frame.traversal_visits) && sp > 0; it++) {\n";
        g.code << "    g_loop_iterations++;\n";
        g.code << countEvent(kEventVisits, "  ");
      } else {
        g.code << "  for (int it = 0; it < " << kSceneOnlyVisits << " && sp > 0; it++) {\n";
      }
      g.code << "    sp--;\n    if (sd[sp] >= " << best << slack << ") continue;\n";
      g.code << "    int ni = sn[sp];\n";
      g.code << "    a = sd_data[" << nb << " + 2 * ni];\n    b = sd_data[" << nb << " + 2 * ni + 1];\n";
      g.code << "    // Far from the nearest box compared with its size: the least box distance\n"
                "    // left is within a factor 2 of the distance; enough for a march step.\n";
      // A blend of children all at least m away is at least m - 1.25 k (each
      // smooth minimum lowers by at most k / 4 and none acts below m - k), so
      // a smooth set takes this exit only where that is at least half of m:
      // a positive bound, never a hit.
      // Nor where what the nodes above take off (ir::Node::lowered: a round
      // of the set) could bring the bound to 0.
      const std::string floor = !(n.lowered < 1e30) ? " && false"
                                : n.lowered > 0        ? " && sm[sp] > " + glslFloat(1.01 * n.lowered) +
                                                      (smooth ? " + 1.25 * k" : "")
                                                       : "";
      g.code << "    if (sm[sp] >= sd[sp] && sd[sp] > " << glslFloat(kFarBoxFactor) << " * distance(a.xyz, b.xyz)"
             << (smooth ? " && sm[sp] >= 2.5 * k" : "") << floor << ") {\n";
      g.code << "      " << best << " = min(" << best << ", sm[sp]" << (smooth ? " - 1.25 * k" : "") << ");\n";
      g.code << "      sp = 0;\n      break;\n    }\n";
      g.code << "    int first = int(a.w), count = int(b.w);\n";
      g.code << "    if (count == 0) {\n";
      g.code << "      int l = ni + 1, r = first;\n";
      g.code << "      float dl = sdBoxSignedDistance(p, sd_data[" << nb << " + 2 * l].xyz, sd_data[" << nb
             << " + 2 * l + 1].xyz);\n";
      g.code << "      float dr = sdBoxSignedDistance(p, sd_data[" << nb << " + 2 * r].xyz, sd_data[" << nb
             << " + 2 * r + 1].xyz);\n";
      g.code << "      bool left_near = dl <= dr;\n";
      g.code << "      int nn = left_near ? l : r, nf = left_near ? r : l;\n";
      g.code << "      float dn = min(dl, dr), df = max(dl, dr);\n";
      g.code << "      // The far child first, so the near one is visited next.\n";
      g.code << "      if (df < " << best << slack << ") {\n";
      g.code << "        sn[sp] = nf;\n        sd[sp] = df;\n        sm[sp] = sp > 0 ? min(sm[sp - 1], df) : df;\n        sp++;\n      }\n";
      g.code << "      if (dn < " << best << slack << ") {\n";
      g.code << "        sn[sp] = nn;\n        sd[sp] = dn;\n        sm[sp] = sp > 0 ? min(sm[sp - 1], dn) : dn;\n        sp++;\n      }\n";
      g.code << "    } else {\n";
      g.code << "      int rec = " << ib << " + first * " << l.stride << ";\n";
      for (unsigned j = 0; j < ir::kBvhLeafSize; ++j) {
        const std::string call =
            one + "(p, rec + " + std::to_string(j * l.stride) + (mat ? ", inherited)" : ")");
        g.code << "      if (" << j << " < count) {\n";
        if (mat) {
          g.code << "        vec2 r = " << call << ";\n";
          if (smooth)
            g.code << "        best = vec2(sdSmoothMin(best.x, r.x, k), r.x < best.x ? r.y : best.y);\n";
          else
            g.code << "        if (r.x < best.x) best = r;\n";
        } else {
          g.code << "        best = " << (smooth ? "sdSmoothMin(best, " + call + ", k)" : "min(best, " + call + ")")
                 << ";\n";
        }
        g.code << "      }\n";
      }
      g.code << "    }\n";
      // Entries the best so far has made useless are dropped here, without
      // spending a loop iteration (a visit) on each.
      g.code << "    // Drop entries no nearer than the best so far (straight-line code: no visits).\n";
      for (int j = 0; j < kPrunesPerVisit; ++j)
        g.code << "    if (sp > 0 && sd[sp - 1] >= " << best << slack << ") sp--;\n";
      g.code << "  }\n";
      g.code << "  // Out of visits (only where the driver caps loops): what is left on the stack is\n"
             << "  // no nearer than its least box" << (smooth ? " (a blend lowers that by at most 1.25 k)" : "")
             << ", a lower bound that march() must not stop on.\n";
      g.code << "  if (sp > 0) {\n    " << best << " = min(" << best << ", sm[sp - 1]" << (smooth ? " - 1.25 * k" : "")
             << ");\n" << (options_.with_kernel ? "    g_bound_only = true;\n" : "") << "  }\n";
      g.code << "  return best;\n}\n";
      functions_ << g.code.str();
      if (l.grid) gridFunction(n, l, mat, name, one, tree);
      ++function_count_;
    }
    const std::string d = var(f, mat ? "m" : "d");
    f.code << "  " << (mat ? "vec2 " : "float ") << d << " = " << name << "(" << p
           << (mat ? ", " + inherited : "") << ");" << lineComment(n) << " instances\n";
    return d;
  }

  // Emits `n` as a function the first time (named after `label`, the
  // definition's name by default) and returns a call of it at `p`.
  std::string callFunction(const ir::Node& n, const std::string& p, Function& f, bool mat,
                           const std::string& inherited, std::string label = "", const std::string& cut = "") {
    if (label.empty()) label = n.definition;
    // A hard union's function takes its caller's cut (1e30: none).
    const bool takes_cut = takesCut(n);
    auto key = std::make_pair(&n, mat);
    auto it = node_functions_.find(key);
    std::string name;
    if (it != node_functions_.end()) {
      name = it->second;
    } else {
      name = (mat ? "sdm_" : "sd_") + label;
      for (const auto& [k, v] : node_functions_)
        if (v == name) name += "_" + std::to_string(node_functions_.size());
      node_functions_[key] = name;
      // Emit the body with the definition stripped so it is not re-entered.
      ir::Node copy = n;
      copy.definition.clear();
      Function g;
      g.code << lineDirective(n);
      g.code << "// " << label << lineComment(n) << "\n";
      g.code << (mat ? "vec2 " : "float ") << name << "(vec3 p" << (mat ? ", float inherited" : "")
             << (takes_cut ? ", float cut" : "") << ") {\n";
      if (takes_cut) cut_ = "cut";
      const std::string r = node(copy, "p", g, mat, mat ? "inherited" : "-1.0");
      g.code << "  return " << r << ";\n}\n";
      functions_ << g.code.str();
      ++function_count_;
    }
    return name + "(" + p + (mat ? ", " + inherited : "") + (takes_cut ? ", " + (cut.empty() ? std::string("1e30") : cut) : "") + ")";
  }

  // A primitive's GLSL function and the shared helpers it calls, once each.
  void needPrimitive(const PrimitiveInfo& info) {
    const std::string source = info.glsl_source;
    if (source.find("sdBox2(") != std::string::npos) needHelper("sdBox2", box2Glsl());
    if (source.find("sdTriangleDistance(") != std::string::npos)
      needHelper("sdTriangleDistance", triangleGlsl());
    needHelper(info.glsl_function, info.glsl_source);
  }

  std::string primitive(const ir::Node& n, const std::string& p, Function& f) {
    const PrimitiveInfo& info = primitiveInfo(n.primitive);
    std::string fn = info.glsl_function;
    if (n.primitive == PrimitiveKind::Menger) {
      needHelper("sdBox2", box2Glsl());
      return menger(n, p, f);
    }
    if (n.primitive == PrimitiveKind::Polygon) return polygon(n, p, f);
    needPrimitive(info);
    std::string call = fn + "(" + p;
    size_t slot = 0;
    for (const ParamSpec& spec : info.params) {
      if (spec.type == ParamType::Vector) {
        ir::Vec3 v{n.args[slot], n.args[slot + 1], n.args[slot + 2]};
        // The plane's normal is normalised here, once, not per evaluation.
        if (n.primitive == PrimitiveKind::Plane && v.isConst())
          v = ir::constantVec(glm::normalize(v.value()));
        call += ", " + v.glsl();
        slot += 3;
      } else if (spec.type == ParamType::Vector2) {
        call += ", vec2(" + n.args[slot].glsl() + ", " + n.args[slot + 1].glsl() + ")";
        slot += 2;
      } else {
        call += ", " + n.args[slot++].glsl();
      }
    }
    call += ")";
    const std::string d = var(f, "d");
    f.code << lineDirective(n) << "  float " << d << " = " << call << ";" << lineComment(n) << " "
           << info.name << "\n";
    if (options_.count_evaluations) f.code << "  g_loop_iterations++;\n";
    return d;
  }

  // A polygon: one unrolled function per distinct point list (and axis,
  // when revolved as a lathe: its edges on the axis left out).
  std::string polygon(const ir::Node& n, const std::string& p, Function& f, double axis = -HUGE_VAL) {
    std::string key;
    for (const glm::dvec2& v : n.points) key += glslFloat(v.x) + "," + glslFloat(v.y) + ";";
    if (axis > -HUGE_VAL) key += "axis " + glslFloat(axis);
    auto [it, fresh] = polygon_names_.try_emplace(key, "sdPolygon" + std::to_string(polygon_names_.size()));
    if (fresh) helpers_ << polygonGlsl(it->second, n.points, axis);
    const std::string d = var(f, "d");
    f.code << lineDirective(n) << "  float " << d << " = " << it->second << "(" << p << ");" << lineComment(n)
           << " polygon\n";
    if (options_.count_evaluations) f.code << "  g_loop_iterations++;\n";
    return d;
  }

  // A mesh's sampled grid, appended to the scene data once per mesh; in the
  // exact mode its hierarchy and triangles too, and a search function.
  std::string mesh(const ir::Node& n, const std::string& p, Function& f) {
    needHelper("sdMeshGrid", meshGridGlsl());
    const MeshShape& m = *n.mesh;
    auto it = mesh_bases_.find(&m);
    if (it == mesh_bases_.end()) {
      const size_t grid = appendMeshGridData(m.grid_layout, m.grid(options_.mesh_grid_cache_version), data_);
      std::string call = "sdMeshGrid(%, " + std::to_string(grid) + ")";
      if (m.mode == MeshMode::Exact) {
        needHelper("sdMeshTriangle2", meshExactHelperGlsl());
        exact_mesh_ = true;
        const MeshExactData at = appendMeshExactData(*m.distance, data_);
        const std::string name = "sdMeshExact" + std::to_string(mesh_bases_.size());
        const bool kernel = options_.with_kernel;
        functions_ << lineDirective(n)
                   << meshExactGlsl(name, *m.distance, m.grid_layout, grid, at,
                                    kernel ? "int(frame.traversal_visits)" : std::to_string(kSceneOnlyVisits),
                                    kernel ? "loopZero()" : "0", kernel);
        ++function_count_;
        call = name + "(%)";
      }
      it = mesh_bases_.emplace(&m, call).first;
    }
    std::string call = it->second;
    call.replace(call.find('%'), 1, p);
    const std::string d = var(f, "d");
    f.code << lineDirective(n) << "  float " << d << " = " << call << ";" << lineComment(n) << " mesh\n";
    if (options_.count_evaluations) f.code << "  g_loop_iterations++;\n";
    return d;
  }
  std::map<const MeshShape*, std::string> mesh_bases_;  // the call, % for the point
  bool exact_mesh_ = false;  // a mesh in the exact mode: its search may end as a bound

  // The Menger sponge, unrolled: `level` is a compile-time constant, and a
  // loop here would count against lavapipe's loop cap at every march step.
  std::string menger(const ir::Node& n, const std::string& p, Function& f) {
    const int level = static_cast<int>(n.args[0].value);
    const std::string name = "sdMenger" + std::to_string(level);
    if (helper_names_.insert(name).second) {
      std::ostringstream h;
      h << "// Menger sponge of level " << level << ", unrolled (see shapes/primitives.cpp).\n";
      h << "float " << name << "(vec3 p, float size) {\n";
      h << "  float half_size = 0.5 * size;\n  vec3 q = abs(p) - half_size;\n";
      h << "  float d = length(max(q, 0.0)) + min(max(q.x, max(q.y, q.z)), 0.0);\n";
      h << "  float cell = size;\n  vec3 r;\n  float w;\n";
      for (int k = 0; k < level; ++k) {
        h << "  r = p + half_size;\n  r = abs(r - cell * floor(r / cell) - 0.5 * cell);\n";
        h << "  w = cell / 6.0;\n";
        h << "  d = max(d, -min(sdBox2(vec2(r.y - w, r.z - w)), min(sdBox2(vec2(r.z - w, r.x - w)), "
             "sdBox2(vec2(r.x - w, r.y - w)))));\n";
        if (k + 1 < level) h << "  cell /= 3.0;\n";
      }
      h << "  return d;\n}\n";
      helpers_ << h.str();
    }
    const std::string d = var(f, "d");
    f.code << "  float " << d << " = " << name << "(" << p << ", " << n.args[1].glsl() << ");"
           << lineComment(n) << " menger\n";
    if (options_.count_evaluations) f.code << "  g_loop_iterations++;\n";
    return d;
  }

  // Whether csg() uses a caller's cut for `n`: a hard union (whose value only
  // lowers its caller's) with a box check in it or in a hard union below it
  // (through rigid transforms), where the cut can skip a child.
  bool takesCut(const ir::Node& n) {
    if (n.kind != ir::NodeKind::Union || !n.smooth.isConst() || n.smooth.value > 0) return false;
    auto it = takes_cut_.find(&n);
    if (it != takes_cut_.end()) return it->second;
    bool uses = false;
    for (const ir::NodeRef& c : n.children) {
      const ir::Node* below = c.get();
      while (keepsDistances(*below) && below->children.size() == 1) below = below->children[0].get();
      uses = uses || boxChecked(*c) || takesCut(*below);
    }
    return takes_cut_[&n] = uses;
  }
  std::map<const ir::Node*, bool> takes_cut_;

  // Whether a union's child `c` gets a box check (csg).
  bool boxChecked(const ir::Node& c) const {
    return (options_.bounding_volumes || (options_.planned_bounds && c.box_check)) &&
           boxCheckCandidate(c, options_.bound_cost_threshold);
  }

  std::string csg(const ir::Node& n, const std::string& p, Function& f, bool mat,
                  const std::string& inherited, std::string cut = "") {
    const bool smooth = !n.smooth.isConst() || n.smooth.value > 0;
    if (!takesCut(n)) cut.clear();
    std::string k;
    if (smooth) {
      needHelper("smooth", kSmoothHelpers);
      k = var(f, "k");
      f.code << "  float " << k << " = " << n.smooth.glsl() << ";\n";
    }
    const std::string acc = var(f, "d");
    const char* type = mat ? "vec2" : "float";
    const std::string dist = mat ? acc + ".x" : acc;
    const bool is_union = n.kind == ir::NodeKind::Union;
    f.code << "  " << type << " " << acc;
    // A union starts from "nothing is near" so every child, the first too,
    // can be skipped by its bound.
    if (is_union) f.code << " = " << (mat ? "vec2(1e30, -1.0)" : "1e30");
    f.code << ";" << lineComment(n) << " "
           << (is_union ? "union" : n.kind == ir::NodeKind::Intersect ? "intersect" : "subtract") << "\n";
    // The operands: the children, or for the pruned root its parts (nested
    // unions flattened), each with its material and bit in a cell's mask.
    struct Operand {
      const ir::Node* node;
      std::string inherited;
      int bit;
    };
    std::vector<Operand> operands;
    std::string mask;
    if (&n == prune_root_) {
      needHelper("prune", prune_helper_.c_str());
      mask = var(f, "pm");
      f.code << "  uvec4 " << mask << " = sdPruneMask(" << p << ");\n";
      for (size_t i = 0; i < prune_->parts.size(); ++i) {
        if (taken_.count(prune_->parts[i].get())) continue;
        const int m = prune_->inherited[i];
        operands.push_back({prune_->parts[i].get(), m >= 0 ? glslFloat(m) : inherited, prune_->bit[i]});
      }
    } else {
      for (const ir::NodeRef& c : n.children) operands.push_back({c.get(), inherited, -1});
    }
    for (size_t i = 0; i < operands.size(); ++i) {
      const ir::Node& c = *operands[i].node;
      const int bit = operands[i].bit;
      if (bit >= 0) {
        // Uniform over the group, as a bound's check: the part runs where some
        // lane's cell needs it, and is skipped where none does.
        ++pruned_checks_;
        char hex[16];
        std::snprintf(hex, sizeof hex, "0x%Xu", 1u << (bit % ir::kPruneBitsPerWord));
        f.code << "  if (subgroupAny((" << mask << "." << "xyzw"[bit / ir::kPruneBitsPerWord] << " & " << hex
               << ") != 0u)) {\n";
      }
      // Bounding volumes, in a union only (where a lower bound of a child
      // keeps the result a lower bound):
      //  - a child whose box is farther than the nearest distance so far
      //    cannot be the minimum: skip it (exact; within k when smooth);
      //  - a child whose box is farther than a margin contributes the box
      //    distance instead of its own (a lower bound; exact near surfaces).
      const bool bound = is_union && boxChecked(c);
      std::string b;
      if (bound) {
        needHelper("sdBound", kAabbHelper);
        ++bounded_;
        b = var(f, "b");
        const dvec3 half = c.bounds.halfSize();
        const double margin = boxCheckMargin(c);
        // Under a deformation the child's field is its raw field (at least the
        // box distance) over the stretch: so is the box distance used for it.
        const double stretch = stretchBelow(c);
        f.code << "  float " << b << " = sdBound(" << p << ", " << vec3Literal(c.bounds.center()) << ", "
               << vec3Literal(half) << ")" << (stretch > 1 ? " * " + glslFloat(1 / stretch) : std::string()) << ";\n";
        // subgroupAny makes the condition uniform: lavapipe (and GPUs) then
        // branch around the subtree when every lane of the group may skip it;
        // a per-lane condition would only mask the lanes and run it anyway.
        // A caller's cut skips more: a child whose box is beyond it cannot
        // lower the caller's union, whatever it does to this one.
        const std::string reach = cut.empty() ? dist : "min(" + dist + ", " + cut + ")";
        f.code << "  if (subgroupAny(" << b << " < " << reach << (smooth ? " + " + k : "") << ")) {\n";
        if (!mat) {
          f.code << "   if (" << b << " > " << glslFloat(margin) << (smooth ? " + " + k : "") << ") {\n";
          f.code << "    " << acc << " = min(" << acc << ", " << b << ");\n";
          f.code << "   } else {\n";
        }
      }
      // A hard union's child that is a hard union (under rigid transforms)
      // may skip what cannot lower this union so far, nor its caller's.
      if (takesCut(n)) cut_ = cut.empty() ? dist : "min(" + dist + ", " + cut + ")";
      std::string r = node(c, p, f, mat, operands[i].inherited);
      if (mat && !isIdentifier(r)) {
        // The material pair is used three times below: a call written out
        // three times is inlined three times (glslang and the driver's NIR
        // inline every call site; only a later CSE may merge the copies).
        const std::string m = var(f, "m");
        f.code << "  vec2 " << m << " = " << r << ";\n";
        r = m;
      }
      const std::string rd = mat ? r + ".x" : r;
      std::ostringstream s;
      if (is_union) {
        if (!mat) {
          s << acc << " = " << (smooth ? "sdSmoothMin(" + acc + ", " + r + ", " + k + ")" : "min(" + acc + ", " + r + ")") << ";";
        } else {
          s << acc << " = vec2(" << (smooth ? "sdSmoothMin(" + dist + ", " + rd + ", " + k + ")" : "min(" + dist + ", " + rd + ")")
            << ", " << rd << " < " << dist << " ? " << r << ".y : " << acc << ".y);";
        }
      } else if (i == 0) {
        s << acc << " = " << r << ";";
      } else if (n.kind == ir::NodeKind::Intersect) {
        if (!mat) {
          s << acc << " = " << (smooth ? "sdSmoothMax(" + acc + ", " + r + ", " + k + ")" : "max(" + acc + ", " + r + ")") << ";";
        } else {
          s << acc << " = vec2(" << (smooth ? "sdSmoothMax(" + dist + ", " + rd + ", " + k + ")" : "max(" + dist + ", " + rd + ")")
            << ", " << rd << " > " << dist << " ? " << r << ".y : " << acc << ".y);";
        }
      } else {
        const std::string neg = "-" + rd;
        s << dist << " = " << (smooth ? "sdSmoothMax(" + dist + ", " + neg + ", " + k + ")" : "max(" + dist + ", " + neg + ")") << ";";
      }
      f.code << "  " << s.str() << "\n";
      if (bound) f.code << (mat ? "  }\n" : "   }\n  }\n");
      if (bit >= 0) f.code << "  }\n";
    }
    return acc;
  }

  std::string domain(const ir::Node& n, const std::string& p, Function& f, bool mat,
                     const std::string& inherited, const std::string& cut = "") {
    const ir::Node& c = *n.children[0];
    const std::string q = var(f, "p");
    std::string scale;  // multiplies the child's distance
    switch (n.kind) {
      case ir::NodeKind::Translate:
        f.code << "  vec3 " << q << " = " << p << " - " << n.vec.glsl() << ";" << lineComment(n) << " translate\n";
        break;
      case ir::NodeKind::Rotate:
        needHelper("rotate", kRotateHelper);
        f.code << "  vec3 " << q << " = sdRotateInverse(" << p << ", " << n.vec.glsl() << ", radians("
               << n.amount.glsl() << "));" << lineComment(n) << " rotate\n";
        break;
      case ir::NodeKind::Scale:
        scale = var(f, "s");
        f.code << "  float " << scale << " = " << n.amount.glsl() << ";\n";
        f.code << "  vec3 " << q << " = " << p << " / " << scale << ";" << lineComment(n) << " scale\n";
        break;
      case ir::NodeKind::ScaleNonUniform: {
        const std::string s = var(f, "s");
        f.code << "  vec3 " << s << " = " << n.vec.glsl() << ";\n";
        f.code << "  vec3 " << q << " = " << p << " / " << s << ";" << lineComment(n)
               << " non-uniform scale (a bound)\n";
        scale = "min(" + s + ".x, min(" + s + ".y, " + s + ".z))";
        break;
      }
      case ir::NodeKind::Affine: {
        std::string e = p;
        if (n.linear != glm::dmat3(1.0)) {
          const glm::dmat3& m = n.linear;
          std::string cols;
          for (int col = 0; col < 3; ++col)
            for (int row = 0; row < 3; ++row)
              cols += (cols.empty() ? "" : ", ") + glslFloat(m[col][row]);
          e = "mat3(" + cols + ") * " + p;
        }
        if (n.offset != dvec3(0)) e += " + " + vec3Literal(n.offset);
        f.code << "  vec3 " << q << " = " << e << ";" << lineComment(n) << " transform\n";
        if (n.scale != 1) scale = glslFloat(n.scale);
        break;
      }
      case ir::NodeKind::Reflect: {
        const std::string nn = vec3Literal(n.vec.value());
        f.code << "  vec3 " << q << " = " << p << " - 2.0 * min(dot(" << p << ", " << nn << ") - "
               << n.amount.glsl() << ", 0.0) * " << nn << ";" << lineComment(n) << " reflect\n";
        break;
      }
      case ir::NodeKind::Elongate:
        f.code << "  vec3 " << q << " = " << p << " - clamp(" << p << ", -" << n.vec.glsl() << ", "
               << n.vec.glsl() << ");" << lineComment(n) << " elongate\n";
        break;
      case ir::NodeKind::Repeat: return repeat(n, p, f, mat, inherited);
      default: break;
    }
    if (keepsDistances(n)) cut_ = cut;
    const std::string r = node(c, q, f, mat, inherited);
    if (scale.empty()) return r;
    if (!mat) return "(" + r + " * " + scale + ")";
    return "vec2(" + r + ".x * " + scale + ", " + r + ".y)";
  }

  std::string repeat(const ir::Node& n, const std::string& p, Function& f, bool mat,
                     const std::string& inherited) {
    const ir::Node& c = *n.children[0];
    const dvec3 cell = n.vec.value();
    static const char* kAxis = "xyz";
    // Per repeated axis: the cell index, and whether the child reaches past
    // its cell (then the cells on both sides are tried too, as in the
    // evaluator: an off-centre child can be nearest from either side).
    std::string index[3];
    int span[3] = {0, 0, 0};
    f.code << "  // line " << n.range.line() << " repeat\n";
    for (int a = 0; a < 3; ++a) {
      if (cell[a] == 0) continue;
      const std::string s = glslFloat(cell[a]);
      // The copy whose centre is nearest (repeatCells, passes.h).
      const RepeatCells r = repeatCells(n, a);
      const std::string x = r.centre == 0 ? p + "." + kAxis[a]
                                          : "(" + p + "." + kAxis[a] + " - " + glslFloat(r.centre) + ")";
      index[a] = var(f, "i");
      if (n.count[a] == 0) {
        f.code << "  float " << index[a] << " = round(" << x << " / " << s << ");\n";
      } else {
        const double half = (n.count[a] - 1) * 0.5;
        f.code << "  float " << index[a] << " = clamp(round(" << x << " / " << s << " + " << glslFloat(half)
               << "), 0.0, " << glslFloat(n.count[a] - 1) << ") - " << glslFloat(half) << ";\n";
      }
      span[a] = r.side;
    }
    auto point = [&](const int d[3]) {
      std::string comps;
      for (int a = 0; a < 3; ++a) {
        std::string comp = p + "." + kAxis[a];
        if (cell[a] != 0) {
          std::string j = index[a];
          if (d[a] != 0) {
            j = index[a] + (d[a] > 0 ? " + " : " - ") + glslFloat(std::abs(d[a]));
            if (n.count[a] > 0) {
              const double half = (n.count[a] - 1) * 0.5;
              j = "clamp(" + j + ", " + glslFloat(-half) + ", " + glslFloat(half) + ")";
            }
            j = "(" + j + ")";
          }
          comp += " - " + glslFloat(cell[a]) + " * " + j;
        }
        comps += (comps.empty() ? "" : ", ") + comp;
      }
      return "vec3(" + comps + ")";
    };
    std::vector<std::string> points;
    for (int dx = -span[0]; dx <= span[0]; ++dx)
      for (int dy = -span[1]; dy <= span[1]; ++dy)
        for (int dz = -span[2]; dz <= span[2]; ++dz) {
          const int d[3] = {dx, dy, dz};
          const std::string q = var(f, "p");
          f.code << "  vec3 " << q << " = " << point(d) << ";\n";
          points.push_back(q);
        }
    if (points.size() == 1) return node(c, points[0], f, mat, inherited);
    // Several cells: evaluate the child through a function, not inlined per cell.
    const std::string label = c.definition.empty() ? "cell" : c.definition;
    const std::string acc = var(f, "d");
    auto eval = [&](const std::string& pt) { return callFunction(c, pt, f, mat, inherited, label); };
    f.code << "  " << (mat ? "vec2 " : "float ") << acc << " = " << eval(points[0]) << ";\n";
    for (size_t i = 1; i < points.size(); ++i) {
      const std::string r = var(f, "r");
      f.code << "  " << (mat ? "vec2 " : "float ") << r << " = " << eval(points[i]) << ";\n";
      if (mat)
        f.code << "  if (" << r << ".x < " << acc << ".x) " << acc << " = " << r << ";\n";
      else
        f.code << "  " << acc << " = min(" << acc << ", " << r << ");\n";
    }
    return acc;
  }

  void lights(std::ostringstream& out) {
    if (scene_.sun) {
      const ir::Sun& s = *scene_.sun;
      out << "const vec3 kSunDir = " << vec3Literal(glm::normalize(s.direction)) << ";\n";
      out << "const float kSunCosAngle = " << glslFloat(std::cos(glm::radians(std::max(s.angle_degrees, 0.05))))
          << ";\n";
      out << "const vec3 kSunRadiance = " << vec3Literal(s.radiance) << ";\n";
    }
    if (!scene_.lights.empty()) {
      const size_t n = scene_.lights.size();
      out << "const int kNumSphereLights = " << n << ";\n";
      out << "const vec4 kSphereLights[kNumSphereLights] = vec4[](";
      for (size_t i = 0; i < n; ++i) {
        const dvec3 c = scene_.lights[i].position;
        out << (i ? ", " : "") << "vec4(" << glslFloat(c.x) << ", " << glslFloat(c.y) << ", "
            << glslFloat(c.z) << ", " << glslFloat(scene_.lights[i].radius) << ")";
      }
      out << ");\n";
      out << "const vec3 kSphereLightRadiance[kNumSphereLights] = vec3[](";
      for (size_t i = 0; i < n; ++i) out << (i ? ", " : "") << vec3Literal(scene_.lights[i].radiance);
      out << ");\n";
    }
  }

  void materials(std::ostringstream& out) {
    static const char* kModel[] = {"MAT_DIFFUSE", "MAT_MIRROR", "MAT_GLASS", "MAT_EMISSIVE", "MAT_METAL"};
    auto literal = [&](const ir::Material& m) {
      return "Material(" + std::string(kModel[static_cast<int>(m.model)]) + ", " +
             vec3Literal(m.albedo.value()) + ", " + vec3Literal(m.emission.value()) + ", " +
             glslFloat(m.ior) + ", " + glslFloat(m.roughness) + ")";
    };
    // Shapes with no material at all are a light grey diffuse (material 0
    // when the scene defines none).
    out << "\nMaterial sdMaterial(int id) {\n";
    if (scene_.materials.empty()) {
      out << "  return Material(MAT_DIFFUSE, vec3(0.75), vec3(0.0), 1.5, 0.0);\n}\n";
      return;
    }
    for (size_t i = 1; i < scene_.materials.size(); ++i)
      out << "  if (id == " << i << ") return " << literal(scene_.materials[i]) << ";  // "
          << scene_.materials[i].name << "\n";
    out << "  return " << literal(scene_.materials[0]) << ";  // " << scene_.materials[0].name << "\n}\n";
    bool unassigned = false;
    emitFieldMaterials(scene_, usedMaterials(scene_, unassigned), texture_bases_, out,
                       helper_names_.count("noise") > 0);
  }

  void sky(std::ostringstream& out, const std::set<std::string>& features) {
    const ir::Sky& s = scene_.sky;
    if (s.map) {
      emitEnvMap(s, env_map_, features, out);
    } else if (!s.gradient()) {
      out << "vec3 sdSky(vec3 dir) { return " << vec3Literal(s.top) << "; }\n";
    } else {
      out << "vec3 sdSky(vec3 dir) { return mix(" << vec3Literal(s.bottom) << ", " << vec3Literal(s.top)
          << ", clamp(dir.y * 0.5 + 0.5, 0.0, 1.0)); }\n";
    }
  }
};

// Which materials some primitive shows, and whether a primitive has none.
std::vector<bool> usedMaterials(const ir::Scene& scene, bool& unassigned) {
  std::vector<bool> used(scene.materials.size(), false);
  unassigned = false;
  std::function<void(const ir::Node&, int)> walk = [&](const ir::Node& n, int inherited) {
    const int m = n.material >= 0 ? n.material : inherited;
    if (n.kind == ir::NodeKind::Primitive) {
      if (m >= 0) used[m] = true;
      else unassigned = true;
    }
    if (n.kind == ir::NodeKind::Instances) {
      // Through the copies' own materials (without them the kernel lost the
      // model of a material only copies use: metal parts of a set drew black).
      eachTemplateMaterial(n, m, [&](const ir::Node& templ, int mi) {
        walk(templ, mi);
        return true;
      });
      return;
    }
    for (const ir::NodeRef& c : n.children) walk(*c, m);
  };
  if (scene.root) walk(*scene.root, -1);
  if (unassigned && !scene.materials.empty()) used[0] = true;  // sdMaterialId falls back to 0
  return used;
}

// Which material models and lights occur, as SDFC_* macro names.
std::set<std::string> sceneFeatures(const ir::Scene& scene, const EmitOptions& options) {
  std::set<std::string> f;
  bool unassigned = false;
  const std::vector<bool> used = usedMaterials(scene, unassigned);
  if (unassigned && scene.materials.empty()) f.insert("SDFC_HAS_DIFFUSE");
  addFieldFeatures(scene, used, f);
  static const char* kNames[] = {"SDFC_HAS_DIFFUSE", "SDFC_HAS_MIRROR", "SDFC_HAS_GLASS",
                                 "SDFC_HAS_EMISSIVE", "SDFC_HAS_METAL"};
  for (size_t i = 0; i < used.size(); ++i)
    if (used[i]) f.insert(kNames[static_cast<int>(scene.materials[i].model)]);
  if (scene.sun) f.insert("SDFC_HAS_SUN");
  if (scene.sky.map) f.insert("SDFC_HAS_ENVMAP");
  if (!scene.lights.empty()) f.insert("SDFC_HAS_SPHERE_LIGHTS");
  if (scene.uses_time) f.insert("SDFC_USES_TIME");
  if (scene.camera.aperture > 0) f.insert("SDFC_HAS_APERTURE");
  if (options.sobol) f.insert("SDFC_SAMPLER_SOBOL");
  return f;
}

}  // namespace

namespace {
const char* const kKernelViewNames[] = {"beauty", "normal",     "steps", "depth",
                                        "albedo", "iterations", "all"};

// The kernel's view macros: SDFC_TRACE keeps the path tracer (and its random
// numbers and BSDFs); SDFC_ALL_VIEWS keeps the run-time view choice; a debug
// view's SDFC_VIEW_* keeps only that view's primary-ray code.
void addViewFeatures(KernelView view, std::set<std::string>& f) {
  switch (view) {
    case KernelView::All: f.insert({"SDFC_TRACE", "SDFC_ALL_VIEWS"}); break;
    case KernelView::Beauty: f.insert("SDFC_TRACE"); break;
    case KernelView::Iterations: f.insert({"SDFC_TRACE", "SDFC_VIEW_ITERATIONS"}); break;
    case KernelView::Normal: f.insert("SDFC_VIEW_NORMAL"); break;
    case KernelView::Steps: f.insert("SDFC_VIEW_STEPS"); break;
    case KernelView::Depth: f.insert("SDFC_VIEW_DEPTH"); break;
    case KernelView::Albedo: f.insert("SDFC_VIEW_ALBEDO"); break;
  }
}
}  // namespace

std::optional<KernelView> kernelViewFromName(const std::string& name) {
  for (int i = 0; i <= static_cast<int>(KernelView::All); ++i)
    if (name == kKernelViewNames[i]) return static_cast<KernelView>(i);
  return std::nullopt;
}

bool countEventFromName(const std::string& name, int& kind, int& quantity) {
  const size_t dot = name.find('.');
  if (dot == std::string::npos) return false;
  const std::string k = name.substr(0, dot), q = name.substr(dot + 1);
  kind = -2;
  quantity = -1;
  for (int i = 0; i < int(std::size(kCountEventKinds)); ++i)
    if (k == kCountEventKinds[i]) kind = i - 1;  // "all" is -1
  for (int i = 0; i < int(std::size(kCountEventQuantities)); ++i)
    if (q == kCountEventQuantities[i]) quantity = i;
  return kind >= -1 && quantity >= 0;
}

const char* kernelViewName(KernelView view) { return kKernelViewNames[static_cast<int>(view)]; }

EmitResult emitGlsl(const ir::Scene& scene, const EmitOptions& options) {
  EmitResult result;
  result.limits = deriveMarchLimits(scene, options.march);
  result.stats.features = sceneFeatures(scene, options);
  addViewFeatures(options.view, result.stats.features);
  if (options.view == KernelView::Beauty && !options.aovs) result.stats.features.insert("SDFC_NO_AOVS");
  if (options.layers && options.with_kernel && options.view == KernelView::Beauty)
    result.stats.features.insert("SDFC_LAYERS");
  SceneWriter writer(scene, options);
  writer.setGlass(result.stats.features.count("SDFC_HAS_GLASS") > 0);
  const std::string scene_code = writer.write(result.limits, result.stats);
  if (writer.hasAnalyticPlanes()) result.stats.features.insert("SDFC_HAS_PLANES");
  if (writer.hasSceneBox()) result.stats.features.insert("SDFC_HAS_SCENE_BOX");
  if (writer.hasRaySkip()) result.stats.features.insert("SDFC_HAS_RAY_SKIP");
  if (writer.hasSphereNormals()) result.stats.features.insert("SDFC_HAS_SPHERE_NORMALS");
  if (writer.hasSphereMaterial()) result.stats.features.insert("SDFC_HAS_SPHERE_MATERIAL");
  if (writer.oneMaterial()) result.stats.features.insert("SDFC_ONE_MATERIAL");
  if (writer.hasSphereHit()) result.stats.features.insert("SDFC_HAS_SPHERE_HIT");
  int count_kind = 0, count_quantity = 0;
  if (options.with_kernel && countEventFromName(options.count_event, count_kind, count_quantity))
    result.stats.features.insert("SDFC_COUNT_EVENTS");
  result.stats.instance_sets = writer.instanceSets();
  // Traversals (instance sets, exact meshes) that may run out of visits where the driver caps loops.
  if (options.with_kernel && (result.stats.instance_sets > 0 || writer.hasExactMesh()))
    result.stats.features.insert("SDFC_HAS_BOUND_ONLY");
  result.stats.traversals_per_evaluation =
      scene.root ? traversalsPerEvaluation(*scene.root, writer.traversalFreeSet()) : 0;
  result.scene_data = writer.takeData();
  std::ostringstream out;
  out << "#version 450\n";
  if (options.line_directives) out << "#extension GL_GOOGLE_cpp_style_line_directive : require\n";
  // subgroupAny / subgroupAll: bounded subtrees and the point-cloud march's fast path.
  if (result.stats.bounded_subtrees > 0 || writer.hasSphereHit() || writer.prunedChecks() > 0)
    out << "#extension GL_KHR_shader_subgroup_vote : require\n";
  out << "// Generated by sdfc. Features:";
  for (const std::string& f : result.stats.features) out << " " << f;
  out << "\n";
  if (options.with_kernel) {
    out << filterFeatures(embeddedSource("shader_interface.h"), result.stats.features);
    out << filterFeatures(embeddedSource("kernel/prelude.glsl"), result.stats.features);
  }
  out << scene_code;
  if (options.with_kernel)
    out << filterFeatures(embeddedSource("kernel/pathtrace.glsl"), result.stats.features);
  result.glsl = out.str();
  return result;
}

}  // namespace sdfc
