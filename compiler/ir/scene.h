// The checked scene: a small IR of shape nodes, materials, lights, camera and
// render settings. Every later stage (passes, evaluator, emitter, mesher)
// reads this, and `--emit ir` prints it (ir/dump.cpp).
#pragma once
#include <glm/glm.hpp>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "diag/source.h"
#include "ir/expr.h"
#include "ir/instances.h"
#include "ir/prune_grid.h"
#include "meshin/mesh_shape.h"
#include "shapes/primitives.h"

namespace sdfc::ir {

struct Vec3 {
  Scalar x, y, z;
  bool isConst() const { return x.isConst() && y.isConst() && z.isConst(); }
  glm::dvec3 at(double time) const { return {x.at(time), y.at(time), z.at(time)}; }
  glm::dvec3 value() const { return {x.value, y.value, z.value}; }
  std::string glsl() const;
  std::string text() const;
};
Vec3 constantVec(glm::dvec3 v);

enum class NodeKind {
  Primitive,
  Union, Intersect, Subtract,  // n-ary CSG; `smooth` > 0 blends
  Translate,                   // child(p - offset)
  Rotate,                      // child(R^T p); R from axis/degrees
  Scale,                       // uniform: child(p / s) * s
  ScaleNonUniform,             // child(p / s) * min(s): a bound
  Affine,                      // fused constant translate/rotate/scale
  Reflect,                     // mirror across a plane, keeping both halves
  Repeat,                      // infinite or limited repetition
  Elongate,                    // child(p - clamp(p, -h, h))
  Morph,                       // t * a + (1 - t) * b
  Round,                       // child - amount: the shape grown by a radius
  Shell,                       // |child| - amount: a wall of half thickness amount
  Extrude,                     // a 2D profile (z = 0) extruded along z over |z| <= amount
  Revolve,                     // a 2D profile at (|p.xz| - amount, p.y, 0): revolved about y
  Twist,                       // child(p turned about y by -amount * p.y degrees): a bound
  Bend,                        // child(p turned about y by amount * p.x degrees): a bound
  Displace,                    // child + amplitude * noise(p * scale), octaves: a bound
  RepeatPolar,                 // count copies around y, nearest of three sectors
  Instances,                   // union of placed copies of children[0], as data
  Mesh,                        // a triangle mesh read from a file (meshin/)
};

struct Node;
using NodeRef = std::shared_ptr<Node>;

struct Node {
  NodeKind kind = NodeKind::Union;
  SourceRange range;
  int material = -1;  // index into Scene::materials; -1 inherits from the parent

  // Primitive
  PrimitiveKind primitive = PrimitiveKind::Sphere;
  std::vector<Scalar> args;  // flattened parameters, in catalogue order

  // CSG: smooth blend radius (0 = sharp)
  Scalar smooth;
  // Translate: offset. Rotate: axis (unit). ScaleNonUniform: factors. Reflect:
  // normal (unit). Repeat: cell size (0 = not repeated along that axis).
  // Elongate: half extents. Displace: x is the noise scale.
  Vec3 vec;
  // Rotate: angle in degrees; Scale: factor; Reflect: offset; Morph: t;
  // Round: radius; Shell: half the wall's thickness; Extrude: half the
  // depth; Revolve: the offset from the axis; Twist, Bend: degrees per unit;
  // Displace: the amplitude (vec.x holds its scale).
  Scalar amount;
  // Repeat: copies per axis (0 = infinite). RepeatPolar: count.x copies.
  // Displace: count.x octaves.
  glm::ivec3 count{0};
  // Affine: local = linear * p + offset; distance = scale * child(local).
  glm::dmat3 linear{1.0};
  glm::dvec3 offset{0.0};
  double scale = 1.0;

  std::vector<NodeRef> children;

  // Twist, Bend (filled by passes/analyze.cpp): the radius about the y axis
  // that holds the child, and the Lipschitz factor of the deformed field
  // within it, which the node divides by (docs/language.md, "Deformations").
  // Displace: deform_lipschitz only (the noise's stretch holds everywhere).
  double deform_radius = 0;
  double deform_lipschitz = 1;
  // Bend: the deformed field is used only near its bounds (passes/deform.h),
  // where its Lipschitz factor is smaller than over the whole disc.
  bool deform_boxed = false;

  // Revolve: its profile is a polygon with edges on the axis (a lathe's
  // profile), which the solid does not have as surface: they are left out
  // of its distance (passes/analyze.cpp), which keeps it exact inside.
  bool lathe = false;

  // Primitive polygon: its corners, constant (shapes/polygon.h).
  std::vector<glm::dvec2> points;

  // Instances: the copies and their hierarchy (children[0] is the template;
  // `smooth` blends them as a union does).
  std::shared_ptr<InstanceSet> instances;
  // Mesh: the triangles, their distance and the shader's form.
  std::shared_ptr<const MeshShape> mesh;

  // The `let` name when this node is a named definition (emitted as a function).
  std::string definition;

  // Filled by passes/analysis: conservative bounds (in this node's parent
  // frame), exactness, Lipschitz constant and evaluation cost.
  Aabb bounds;
  bool exact = true;
  double lipschitz = 1.0;
  double cost = 0;
  // The most the nodes above may lower this node's field before the march
  // compares it with 0 (a round's radius, a shell's half wall, a displace's
  // amplitude, 1.25 k of a smooth blend), in this node's units. Where the
  // node stands in a lower bound for its field (an instance grid's reach, a
  // hierarchy's box, a union's box check), the bound must exceed this, or
  // the field above would cross 0 where the surface is not (passes/analyze.cpp).
  double lowered = 0;
  // Filled by passes/bounds_plan.cpp on a CPU device: the union above checks
  // this child's box first (box_check), and the share of the sampled steps
  // that would skip it (-1: not sampled).
  bool box_check = false;
  double box_check_skips = -1;
  // The root union only (passes/prune_grid.cpp): which parts each cell of a
  // grid over the scene needs.
  std::shared_ptr<const PruneGrid> prune;
};

// A 2D profile (a profile primitive, or CSG and planar transforms of them):
// only extrude and revolve take one, and they evaluate it at z = 0.
inline bool isProfile(const Node& n) {
  if (n.kind == NodeKind::Primitive) return primitiveInfo(n.primitive).profile;
  if (n.kind == NodeKind::Extrude || n.kind == NodeKind::Revolve || n.kind == NodeKind::Instances ||
      n.children.empty())
    return false;
  return isProfile(*n.children[0]);
}

// The template instance i of Instances node n is a copy of.
inline const Node& templateOf(const Node& n, size_t i) { return *n.children[n.instances->instances[i].templ]; }
// A primitive template whose arguments each instance carries (set.params).
inline bool takesParams(const InstanceSet& set, const Node& templ) {
  return set.param_count > 0 && templ.kind == NodeKind::Primitive && templ.definition.empty();
}

// A point cloud: the copies of an Instances node are one sphere of constant
// radius placed by offsets alone (no rotation or scale, no per-instance
// parameters). The grid ranks its spheres by their own distance
// (passes/instance_grid.cpp); the emitter gives it fixed slots, analytic ray
// hits and radial normals.
inline bool isSphereCloud(const InstanceSet& set, const Node& templ) {
  for (const Instance& i : set.instances)
    if (i.templ != 0) return false;  // a mixed set
  return set.transforms.empty() && set.param_count == 0 && templ.kind == NodeKind::Primitive &&
         templ.primitive == PrimitiveKind::Sphere && !templ.args.empty() && templ.args[0].isConst();
}

enum class MaterialModel { Diffuse = 0, Mirror = 1, Glass = 2, Emissive = 3, Metal = 4 };

// A colour that varies over the surface, of the world point (docs/language.md,
// "Colour fields"): mix(a, b, t) with t in [0, 1] from one closed form per
// kind. The evaluator (eval/color_field.cpp) computes it in float64, the
// emitter in GLSL; noise is the gradient noise of eval/noise.cpp and
// emit/kernel/noise.glsl.
enum class FieldKind { Checker = 0, Stripes = 1, Gradient = 2, Noise = 3, Texture = 4 };

// An image read at check time for texture(file: ...): linear RGB, float32
// (what the shader reads), rows from the top.
struct TextureImage {
  std::string path;
  int width = 0, height = 0;
  std::vector<float> rgb;  // width * height * 3
};

struct ColorField {
  FieldKind kind = FieldKind::Checker;
  SourceRange range;
  Vec3 a, b;
  // Stripes, gradient: the unit direction the colour changes along.
  glm::dvec3 axis{0, 1, 0};
  // Checker: cell size. Stripes: period. Noise: frequency (cycles per unit).
  Scalar size;
  // Gradient: where t is 0 and where it is 1 along the axis.
  Scalar from, to;
  // Noise: octaves of the fractal sum, 1 to 8.
  int octaves = 4;
  // Texture: the image, repeated every `size` units, projected on the three
  // axis planes and blended by the normal (triplanar).
  std::shared_ptr<const TextureImage> image;
};
const char* fieldKindName(FieldKind kind);

struct Material {
  std::string name;
  SourceRange range;
  MaterialModel model = MaterialModel::Diffuse;
  Vec3 albedo;    // diffuse albedo, mirror tint, glass tint, metal F0
  Vec3 emission;  // emissive: colour * strength
  double ior = 1.5;
  double roughness = 0;  // metal: GGX alpha
  // Set when the colour (albedo, tint, or emissive colour) is a field; it then
  // stands for `albedo`, or for `emission` / field_scale (the strength).
  std::shared_ptr<const ColorField> field;
  double field_scale = 1;
};

struct Camera {
  glm::dvec3 position{0, 1, 6}, target{0, 0, 0}, up{0, 1, 0};
  double fov_degrees = 40;
  double aperture = 0, focus_distance = 0;
};

struct Sky {
  glm::dvec3 top{0.6, 0.75, 1.0}, bottom{0.6, 0.75, 1.0};  // equal: constant sky
  bool gradient() const { return top != bottom; }
  // sky(map: "studio.exr"): an equirectangular HDR image, y up, in place of
  // the colours (docs/lighting.md); rotation turns it about +y, in degrees.
  std::shared_ptr<const TextureImage> map;
  double rotation_degrees = 0, strength = 1;
};

struct Sun {
  glm::dvec3 direction{0.3, 1, 0.2};  // towards the sun, unit
  double angle_degrees = 2;             // angular radius
  glm::dvec3 radiance{3, 3, 3};         // colour * strength
};

struct SphereLight {
  glm::dvec3 position{0};
  double radius = 0.5;
  glm::dvec3 radiance{10};
};

struct RenderSettings {
  int width = 640, height = 360, spp = 16, bounces = 3, light_samples = 1;
  bool spp_given = false;  // render(spp: ...) in the file (api/render_defaults.h says which decided)
};

struct Scene {
  NodeRef root;  // null when the file has no scene
  std::vector<Material> materials;
  Camera camera;
  Sky sky;
  std::optional<Sun> sun;
  std::vector<SphereLight> lights;
  RenderSettings render;
  bool uses_time = false;
  // Where the scene's frame has its origin in the world: coordinates here are
  // world minus origin (passes/rebase.cpp moves a far scene to its camera).
  glm::dvec3 origin{0.0};
  // Files brought in by `import` (ranges and diagnostics point into them).
  std::vector<std::shared_ptr<SourceFile>> imported_sources;
  // Data files the scene reads (meshes, textures, point lists), resolved as
  // opened: the viewer reloads when one of them is saved.
  std::vector<std::string> data_files;
};

// Stable text dump for --emit ir and for pass tests (text in, text out).
std::string dump(const Scene& scene);
std::string dumpNode(const Node& node, int indent = 0);

}  // namespace sdfc::ir
