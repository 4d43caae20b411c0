// The IR's text form: stable (fixed precision, fixed field order), so pass
// tests compare text in with text out and `--emit ir` is readable.
#include <cmath>
#include <algorithm>
#include <cstdio>
#include <glm/gtc/matrix_access.hpp>
#include <sstream>

#include "ir/scene.h"
#include "meshin/mesh_exact.h"

namespace sdfc::ir {
namespace {

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}
std::string vec(glm::dvec3 v) { return "[" + num(v.x) + ", " + num(v.y) + ", " + num(v.z) + "]"; }

const char* kindName(NodeKind k) {
  switch (k) {
    case NodeKind::Primitive: return "primitive";
    case NodeKind::Union: return "union";
    case NodeKind::Intersect: return "intersect";
    case NodeKind::Subtract: return "subtract";
    case NodeKind::Translate: return "translate";
    case NodeKind::Rotate: return "rotate";
    case NodeKind::Scale: return "scale";
    case NodeKind::ScaleNonUniform: return "scale_nonuniform";
    case NodeKind::Affine: return "affine";
    case NodeKind::Reflect: return "reflect";
    case NodeKind::Repeat: return "repeat";
    case NodeKind::Elongate: return "elongate";
    case NodeKind::Morph: return "morph";
    case NodeKind::Round: return "round";
    case NodeKind::Shell: return "shell";
    case NodeKind::Extrude: return "extrude";
    case NodeKind::Revolve: return "revolve";
    case NodeKind::Twist: return "twist";
    case NodeKind::Bend: return "bend";
    case NodeKind::Displace: return "displace";
    case NodeKind::RepeatPolar: return "repeat_polar";
    case NodeKind::Instances: return "instances";
    case NodeKind::Mesh: return "mesh";
  }
  return "?";
}

const char* modelName(MaterialModel m) {
  switch (m) {
    case MaterialModel::Diffuse: return "diffuse";
    case MaterialModel::Mirror: return "mirror";
    case MaterialModel::Glass: return "glass";
    case MaterialModel::Emissive: return "emissive";
    case MaterialModel::Metal: return "metal";
  }
  return "?";
}

std::string fieldText(const ColorField& f) {
  std::ostringstream out;
  out << fieldKindName(f.kind) << "(" << f.a.text() << ", " << f.b.text();
  switch (f.kind) {
    case FieldKind::Checker: out << ", size: " << f.size.text(); break;
    case FieldKind::Stripes: out << ", axis: " << vec(f.axis) << ", period: " << f.size.text(); break;
    case FieldKind::Gradient:
      out << ", axis: " << vec(f.axis) << ", from: " << f.from.text() << ", to: " << f.to.text();
      break;
    case FieldKind::Noise: out << ", scale: " << f.size.text() << ", octaves: " << f.octaves; break;
    case FieldKind::Texture:
      return "texture(file: " + f.image->path + " " + std::to_string(f.image->width) + "x" +
             std::to_string(f.image->height) + ", projection: triplanar, size: " + f.size.text() + ")";
  }
  out << ")";
  return out.str();
}

}  // namespace

const char* fieldKindName(FieldKind kind) {
  switch (kind) {
    case FieldKind::Checker: return "checker";
    case FieldKind::Stripes: return "stripes";
    case FieldKind::Gradient: return "gradient";
    case FieldKind::Noise: return "noise";
    case FieldKind::Texture: return "texture";
  }
  return "?";
}

std::string Vec3::glsl() const {
  if (isConst() && x.value == y.value && y.value == z.value) return "vec3(" + x.glsl() + ")";
  return "vec3(" + x.glsl() + ", " + y.glsl() + ", " + z.glsl() + ")";
}
std::string Vec3::text() const { return "[" + x.text() + ", " + y.text() + ", " + z.text() + "]"; }
Vec3 constantVec(glm::dvec3 v) { return {constant(v.x), constant(v.y), constant(v.z)}; }

std::string dumpNode(const Node& n, int indent) {
  std::ostringstream out;
  out << std::string(indent * 2, ' ');
  if (n.kind == NodeKind::Primitive) {
    const PrimitiveInfo& info = primitiveInfo(n.primitive);
    out << info.name << "(";
    size_t slot = 0;
    for (size_t i = 0; i < info.params.size(); ++i) {
      out << (i ? ", " : "") << info.params[i].name << ": ";
      if (info.params[i].type == ParamType::Vector) {
        out << "[" << n.args[slot].text() << ", " << n.args[slot + 1].text() << ", "
            << n.args[slot + 2].text() << "]";
        slot += 3;
      } else if (info.params[i].type == ParamType::Vector2) {
        out << "[" << n.args[slot].text() << ", " << n.args[slot + 1].text() << "]";
        slot += 2;
      } else if (info.params[i].type == ParamType::Points) {
        out << "[";
        for (size_t k = 0; k < n.points.size(); ++k)
          out << (k ? ", " : "") << "[" << n.points[k].x << ", " << n.points[k].y << "]";
        out << "]";
      } else {
        out << n.args[slot++].text();
      }
    }
    out << ")";
  } else {
    out << kindName(n.kind);
    switch (n.kind) {
      case NodeKind::Union:
      case NodeKind::Intersect:
      case NodeKind::Subtract:
        if (!n.smooth.isConst() || n.smooth.value > 0) out << " smooth=" << n.smooth.text();
        break;
      case NodeKind::Translate:
      case NodeKind::ScaleNonUniform:
      case NodeKind::Elongate: out << " " << n.vec.text(); break;
      case NodeKind::Rotate: out << " axis=" << n.vec.text() << " degrees=" << n.amount.text(); break;
      case NodeKind::Scale: out << " " << n.amount.text(); break;
      case NodeKind::Reflect: out << " normal=" << n.vec.text() << " offset=" << n.amount.text(); break;
      case NodeKind::Repeat:
        out << " cell=" << n.vec.text() << " count=[" << n.count.x << ", " << n.count.y << ", "
            << n.count.z << "]";
        break;
      case NodeKind::Morph: out << " t=" << n.amount.text(); break;
      case NodeKind::Round: out << " radius=" << n.amount.text(); break;
      case NodeKind::Shell: out << " half-thickness=" << n.amount.text(); break;
      case NodeKind::Extrude: out << " half-depth=" << n.amount.text(); break;
      case NodeKind::Revolve: out << " offset=" << n.amount.text(); break;
      case NodeKind::Twist: out << " degrees-per-unit=" << n.amount.text(); break;
      case NodeKind::Bend:
        out << " degrees-per-unit=" << n.amount.text() << " stretch=" << n.deform_lipschitz;
        break;
      case NodeKind::Displace:
        out << " amplitude=" << n.amount.text() << " scale=" << n.vec.x.text() << " octaves=" << n.count.x
            << " stretch=" << n.deform_lipschitz;
        break;
      case NodeKind::RepeatPolar: out << " count=" << n.count.x; break;
      case NodeKind::Instances: {
        const InstanceSet& set = *n.instances;
        out << " " << set.size() << " (data form: " << set.origin << "; " << set.nodes.size()
            << " hierarchy nodes, depth " << set.depth << ", per-instance params " << set.param_count
            << ", transforms " << set.transforms.size();
        if (!set.grid.empty()) {
          // The grid's shape, and how often a cell is split or left to the hierarchy.
          size_t listed = 0, listing = 0, split = 0, crowded = 0;
          for (std::int32_t c : set.grid.count) {
            if (c == kGridSplit) ++split;
            else if (c < 0) ++crowded;
            else {
              listed += size_t(c);
              ++listing;
            }
          }
          char buf[200];
          std::snprintf(buf, sizeof buf,
                        "; %sgrid %dx%dx%d cells of %g, lists of %.2f on average, %zu split, %zu crowded",
                        set.grid.blend ? "blend " : "",
                        set.grid.dims.x, set.grid.dims.y, set.grid.dims.z, set.grid.cell,
                        double(listed) / double(std::max<size_t>(listing, 1)), split, crowded);
          out << buf;
        }
        out << ")";
        if (!n.smooth.isConst() || n.smooth.value > 0) out << " smooth=" << n.smooth.text();
        break;
      }
      case NodeKind::Mesh: {
        // What was read, and the shader's form with its error bound.
        const MeshShape& m = *n.mesh;
        const MeshGridLayout& g = m.grid_layout;
        char buf[600];
        const std::string shape =
            m.boundary_edges > 0 ? std::to_string(m.boundary_edges) + " boundary edges"
            : m.flipped_edges > 0 ? "closed, " + std::to_string(m.flipped_edges) + " edges between faces facing opposite ways"
                                  : "closed";
        std::snprintf(buf, sizeof buf, " \"%s\" (%s, %zu triangles, %s; %zu hierarchy nodes, depth %d; shader: ",
                      m.file.c_str(), m.format.c_str(), m.triangles, shape.c_str(), m.distance->nodes().size(),
                      m.distance->depth());
        out << buf;
        if (m.mode == MeshMode::Exact)
          std::snprintf(buf, sizeof buf,
                        "exact (%s): the nearest triangle within %g of the surface, signed by the grid where "
                        "|grid| > %g, else by the nearest feature's pseudo-normal; farther, the grid less %g; grid ",
                        m.mode_reason.c_str(), kMeshExactNear * g.errorBound(), g.errorBound(), g.errorBound());
        else
          std::snprintf(buf, sizeof buf, "grid (%s) ", m.mode_reason.c_str());
        out << buf;
        std::snprintf(buf, sizeof buf,
                      "%dx%dx%d corners of %g, band %g, error <= %g (sqrt 3 / 2 cell), interpolant Lipschitz <= "
                      "1.732; outside it the mesh box's distance)",
                      g.dims.x, g.dims.y, g.dims.z, g.cell, g.band, g.errorBound());
        out << buf;
        break;
      }
      case NodeKind::Affine: {
        const glm::dmat3& m = n.linear;
        out << " linear=[" << vec(glm::row(m, 0)) << ", " << vec(glm::row(m, 1)) << ", "
            << vec(glm::row(m, 2)) << "] offset=" << vec(n.offset) << " scale=" << num(n.scale);
        break;
      }
      default: break;
    }
  }
  if (n.material >= 0) out << " material=" << n.material;
  if (!n.definition.empty()) out << " def=" << n.definition;
  out << "  # line " << n.range.line();
  if (!n.exact) out << ", bound";
  if (n.lipschitz != 1.0) out << ", lipschitz " << num(n.lipschitz);
  if (n.box_check_skips >= 0)
    out << (n.box_check ? ", box check" : ", no box check") << " (skips " << num(std::round(n.box_check_skips * 100))
        << "% of sampled steps)";
  if (n.bounds.finite())
    out << ", bounds " << vec(n.bounds.lo) << ".." << vec(n.bounds.hi);
  out << "\n";
  if (n.prune) {
    // What the prune grid (`--prune`) found.
    const PruneGrid& g = *n.prune;
    char buf[400];
    std::snprintf(buf, sizeof buf,
                  "%s# prune grid %dx%dx%d cells of %g over %zu of %zu parts: a cell keeps %.0f%% of their cost "
                  "(%.0f%% near a surface); built in %.0f ms\n",
                  std::string(indent * 2 + 2, ' ').c_str(), g.dims.x, g.dims.y, g.dims.z, g.cell, g.prunedParts(),
                  g.parts.size(), 100 * g.kept_cost, 100 * g.kept_cost_near, 1000 * g.build_seconds);
    out << buf;
  }
  for (const NodeRef& c : n.children) out << dumpNode(*c, indent + 1);
  return out.str();
}

std::string dump(const Scene& s) {
  std::ostringstream out;
  const Camera& c = s.camera;
  out << "camera position=" << vec(c.position) << " target=" << vec(c.target) << " up=" << vec(c.up)
      << " fov=" << num(c.fov_degrees) << " aperture=" << num(c.aperture)
      << " focus=" << num(c.focus_distance) << "\n";
  out << "render size=" << s.render.width << "x" << s.render.height << " spp=" << s.render.spp
      << " bounces=" << s.render.bounces << " light_samples=" << s.render.light_samples << "\n";
  if (s.sky.map)
    out << "sky map=" << s.sky.map->width << "x" << s.sky.map->height << " rotation=" << num(s.sky.rotation_degrees)
        << " strength=" << num(s.sky.strength) << "\n";
  else
    out << "sky top=" << vec(s.sky.top) << " bottom=" << vec(s.sky.bottom) << "\n";
  if (s.sun)
    out << "sun direction=" << vec(s.sun->direction) << " angle=" << num(s.sun->angle_degrees)
        << " radiance=" << vec(s.sun->radiance) << "\n";
  for (const SphereLight& l : s.lights)
    out << "light position=" << vec(l.position) << " radius=" << num(l.radius)
        << " radiance=" << vec(l.radiance) << "\n";
  for (size_t i = 0; i < s.materials.size(); ++i) {
    const Material& m = s.materials[i];
    out << "material " << i << " " << (m.name.empty() ? "-" : m.name) << " " << modelName(m.model)
        << " albedo=" << vec(m.albedo.value()) << " emission=" << vec(m.emission.value());
    if (m.model == MaterialModel::Glass) out << " ior=" << num(m.ior);
    if (m.model == MaterialModel::Metal) out << " roughness=" << num(m.roughness);
    if (m.field) out << " field=" << fieldText(*m.field) << (m.field_scale != 1 ? " * " + num(m.field_scale) : "");
    out << "\n";
  }
  if (s.uses_time) out << "uses time\n";
  if (s.origin != glm::dvec3(0)) {
    // Every digit: a tool adding it back to the camera line gets the world's.
    char buf[96];
    std::snprintf(buf, sizeof buf, "origin [%.17g, %.17g, %.17g]", s.origin.x, s.origin.y, s.origin.z);
    out << buf << " (the camera's frame: world minus origin)\n";
  }
  if (s.root) out << "scene\n" << dumpNode(*s.root, 1);
  return out.str();
}

}  // namespace sdfc::ir
