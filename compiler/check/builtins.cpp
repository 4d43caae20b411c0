#include "check/builtins.h"

#include "ir/expr.h"

namespace sdfc {
namespace {

constexpr bool kRequired = true, kOptional = false, kTime = true, kConstant = false;

ArgSpec colour(const char* name) {
  return {name, ArgType::Vector3, ValueRule::NonNegative, kOptional, kConstant};
}

// A material's colour: constant, or a colour field.
ArgSpec surfaceColour(const char* name) {
  return {name, ArgType::Colour, ValueRule::NonNegative, kOptional, kConstant};
}

// The two colours a field blends between: they may vary with time.
ArgSpec fieldColour(const char* name) {
  return {name, ArgType::Vector3, ValueRule::NonNegative, kRequired, kTime};
}

}  // namespace

const std::vector<BuiltinSignature>& builtinSignatures() {
  static const std::vector<BuiltinSignature> signatures = {
      // CSG: every child counts; `smooth` blends with a radius.
      {"union", BuiltinCategory::Operator,
       {{"smooth", ArgType::Number, ValueRule::NonNegative, kOptional, kTime}}, "union of the block"},
      {"intersect", BuiltinCategory::Operator,
       {{"smooth", ArgType::Number, ValueRule::NonNegative, kOptional, kTime}}, "intersection of the block"},
      {"subtract", BuiltinCategory::Operator,
       {{"smooth", ArgType::Number, ValueRule::NonNegative, kOptional, kTime}},
       "the first shape minus the others"},
      {"morph", BuiltinCategory::Operator, {{"t", ArgType::Number, ValueRule::Any, kRequired, kTime}},
       "t * first + (1 - t) * second"},
      // Domain operations.
      {"translate", BuiltinCategory::Operator,
       {{"offset", ArgType::Vector3, ValueRule::Any, kRequired, kTime}}, "move by offset"},
      {"rotate", BuiltinCategory::Operator,
       {{"axis", ArgType::Vector3, ValueRule::Any, kOptional, kConstant, true},
        {"degrees", ArgType::Number, ValueRule::Any, kOptional, kTime},
        {"euler", ArgType::Vector3, ValueRule::Any, kOptional, kTime}},
       "rotate about an axis, or by Euler angles (x, then y, then z)"},
      {"scale", BuiltinCategory::Operator, {{"factor", ArgType::Any, ValueRule::Positive, kRequired, kTime}},
       "scale uniformly (a number) or per axis (a vector: a bound)"},
      {"reflect", BuiltinCategory::Operator,
       {{"normal", ArgType::Vector3, ValueRule::Any, kRequired, kConstant, true},
        {"offset", ArgType::Number, ValueRule::Any, kOptional, kConstant}},
       "mirror the half-space behind the plane onto the front"},
      {"repeat", BuiltinCategory::Operator,
       {{"cell", ArgType::Vector3, ValueRule::NonNegative, kRequired, kConstant},
        {"count", ArgType::Vector3, ValueRule::NonNegative, kOptional, kConstant}},
       "repeat in cells (0 = not along that axis), count copies per axis (0 = infinite)"},
      {"instances", BuiltinCategory::Operator,
       {{"positions", ArgType::Any, ValueRule::Any, kRequired, kConstant},
        {"smooth", ArgType::Number, ValueRule::NonNegative, kOptional, kConstant}},
       "the block's shape at each position of a list or file(\"points.csv\")"},
      {"mesh", BuiltinCategory::Operator,
       {{"file", ArgType::Any, ValueRule::Any, kRequired, kConstant}},
       "a triangle mesh read from an STL, OBJ, glTF or GLB file beside the scene (docs/mesh_in.md)"},
      {"elongate", BuiltinCategory::Operator,
       {{"amount", ArgType::Vector3, ValueRule::NonNegative, kRequired, kTime}},
       "stretch by inserting `amount` of length at the centre"},
      // Offsets of any shape.
      {"round", BuiltinCategory::Operator,
       {{"radius", ArgType::Number, ValueRule::NonNegative, kRequired, kTime}},
       "grow the shape by `radius`: edges and corners become rounded"},
      {"shell", BuiltinCategory::Operator,
       {{"thickness", ArgType::Number, ValueRule::Positive, kRequired, kTime}},
       "a wall of `thickness` centred on the surface"},
      // 2D profiles into solids.
      {"extrude", BuiltinCategory::Operator,
       {{"depth", ArgType::Number, ValueRule::Positive, kRequired, kTime}},
       "the block's 2D profile extruded along z over `depth`, centred"},
      {"revolve", BuiltinCategory::Operator,
       {{"offset", ArgType::Number, ValueRule::Any, kOptional, kTime}},
       "the block's 2D profile revolved about the y axis, its x measured from `offset` out"},
      // Deformations (bounds: the distance is divided by their stretch).
      {"twist", BuiltinCategory::Operator,
       {{"rate", ArgType::Number, ValueRule::Any, kRequired, kTime}},
       "twist about the y axis by `rate` degrees per unit of height (a bound)"},
      {"bend", BuiltinCategory::Operator,
       {{"rate", ArgType::Number, ValueRule::Any, kRequired, kTime}},
       "bend about the y axis by `rate` degrees per unit along x: the ends of a bar on x curl towards -z (a bound)"},
      {"displace", BuiltinCategory::Operator,
       {{"amplitude", ArgType::Number, ValueRule::Any, kRequired, kTime},
        {"scale", ArgType::Number, ValueRule::Positive, kOptional, kTime},
        {"octaves", ArgType::Number, ValueRule::Positive, kOptional, kConstant}},
       "move the surface by `amplitude` times gradient noise of the point times `scale`, summed over `octaves` "
       "(a bound)"},
      {"repeat_polar", BuiltinCategory::Operator,
       {{"count", ArgType::Number, ValueRule::Positive, kRequired, kConstant}},
       "`count` copies evenly around the y axis, the shape as placed (off the axis on +x) being one"},
      // Materials.
      {"diffuse", BuiltinCategory::Material, {surfaceColour("albedo")}, "Lambertian"},
      {"mirror", BuiltinCategory::Material, {surfaceColour("tint")}, "perfect specular reflection"},
      {"glass", BuiltinCategory::Material,
       {{"ior", ArgType::Number, ValueRule::Positive, kOptional, kConstant}, surfaceColour("tint")},
       "dielectric with Fresnel reflection and refraction"},
      {"emissive", BuiltinCategory::Material,
       {surfaceColour("color"), {"strength", ArgType::Number, ValueRule::NonNegative, kOptional, kConstant}},
       "emits color * strength"},
      {"metal", BuiltinCategory::Material,
       {surfaceColour("albedo"), {"roughness", ArgType::Number, ValueRule::NonNegative, kOptional, kConstant}},
       "GGX microfacet conductor"},
      // Colour fields (a material's colour varying with the world point).
      {"checker", BuiltinCategory::Field,
       {fieldColour("a"), fieldColour("b"), {"size", ArgType::Number, ValueRule::Positive, kOptional, kTime}},
       "a 3D checkerboard of cubes of side size: a, then b"},
      {"stripes", BuiltinCategory::Field,
       {fieldColour("a"), fieldColour("b"), {"axis", ArgType::Vector3, ValueRule::Any, kOptional, kConstant, true},
        {"period", ArgType::Number, ValueRule::Positive, kOptional, kTime}},
       "bands across axis: a for the first half of each period, then b"},
      {"gradient", BuiltinCategory::Field,
       {fieldColour("a"), fieldColour("b"), {"axis", ArgType::Vector3, ValueRule::Any, kOptional, kConstant, true},
        {"from", ArgType::Number, ValueRule::Any, kOptional, kTime},
        {"to", ArgType::Number, ValueRule::Any, kOptional, kTime}},
       "a at from along axis, b at to, linear between"},
      {"noise", BuiltinCategory::Field,
       {fieldColour("a"), fieldColour("b"), {"scale", ArgType::Number, ValueRule::Positive, kOptional, kTime},
        {"octaves", ArgType::Number, ValueRule::Positive, kOptional, kConstant}},
       "gradient noise of frequency scale, octaves 1 to 8, from a to b"},
      {"texture", BuiltinCategory::Field,
       {{"file", ArgType::Any, ValueRule::Any, kRequired, kConstant},
        {"projection", ArgType::Any, ValueRule::Any, kOptional, kConstant},
        {"size", ArgType::Number, ValueRule::Positive, kOptional, kTime}},
       "a PNG or EXR image on the three axis planes blended by the normal (triplanar), repeating every size"},
      // Settings (statements).
      {"camera", BuiltinCategory::Setting,
       {{"position", ArgType::Vector3, ValueRule::Any, kOptional, kConstant},
        {"target", ArgType::Vector3, ValueRule::Any, kOptional, kConstant},
        {"up", ArgType::Vector3, ValueRule::Any, kOptional, kConstant, true},
        {"fov", ArgType::Number, ValueRule::Positive, kOptional, kConstant},
        {"aperture", ArgType::Number, ValueRule::NonNegative, kOptional, kConstant},
        {"focus", ArgType::Number, ValueRule::Positive, kOptional, kConstant}},
       "pinhole or thin-lens camera; fov is vertical, in degrees"},
      {"render", BuiltinCategory::Setting,
       {{"size", ArgType::Any, ValueRule::Any, kOptional, kConstant},
        {"spp", ArgType::Number, ValueRule::Positive, kOptional, kConstant},
        {"bounces", ArgType::Number, ValueRule::NonNegative, kOptional, kConstant},
        {"light_samples", ArgType::Number, ValueRule::NonNegative, kOptional, kConstant}},
       "render defaults, overridable on the command line"},
      {"sky", BuiltinCategory::Setting,
       {colour("color"), colour("top"), colour("bottom"), {"map", ArgType::Any, ValueRule::Any, kOptional, kConstant},
        {"rotation", ArgType::Number, ValueRule::Any, kOptional, kConstant},
        {"strength", ArgType::Number, ValueRule::NonNegative, kOptional, kConstant}},
       "constant or vertical-gradient environment, or an equirectangular HDR map (EXR or .hdr, y up) "
       "turned by rotation degrees about y and scaled by strength"},
      {"sun", BuiltinCategory::Setting,
       {{"direction", ArgType::Vector3, ValueRule::Any, kOptional, kConstant, true},
        {"angle", ArgType::Number, ValueRule::NonNegative, kOptional, kConstant}, colour("color"),
        {"strength", ArgType::Number, ValueRule::NonNegative, kOptional, kConstant}},
       "distant disc light; angle is its angular radius in degrees"},
      {"light", BuiltinCategory::Setting,
       {{"position", ArgType::Vector3, ValueRule::Any, kRequired, kConstant},
        {"radius", ArgType::Number, ValueRule::Positive, kOptional, kConstant}, colour("color"),
        {"strength", ArgType::Number, ValueRule::NonNegative, kOptional, kConstant}},
       "spherical area light"},
  };
  return signatures;
}

const BuiltinSignature* findBuiltin(const std::string& name) {
  for (const BuiltinSignature& s : builtinSignatures())
    if (name == s.name) return &s;
  return nullptr;
}

bool isSettingName(const std::string& name) {
  const BuiltinSignature* s = findBuiltin(name);
  return s && s->category == BuiltinCategory::Setting;
}

bool isBuiltinCallable(const std::string& name) {
  return findBuiltin(name) || findPrimitive(name) || ir::mathFunctionArity(name) >= 0 ||
         name == "scene";
}

bool isReservedName(const std::string& name) {
  return isBuiltinCallable(name) || name == "time" || name == "pi" || name == "file";
}

std::vector<std::string> allCallableNames() {
  std::vector<std::string> names;
  for (const BuiltinSignature& s : builtinSignatures()) names.push_back(s.name);
  for (const PrimitiveInfo& p : primitiveCatalogue()) names.push_back(p.name);
  for (const std::string& f : ir::mathFunctionNames()) names.push_back(f);
  names.push_back("scene");
  return names;
}

ArgSpec argSpecOf(const ParamSpec& p, const PrimitiveInfo& info) {
  ArgSpec a{p.name,
            p.type == ParamType::Vector    ? ArgType::Vector3
            : p.type == ParamType::Vector2 ? ArgType::Vector2
            : p.type == ParamType::Points  ? ArgType::Any
                                           : ArgType::Number,
            ValueRule::Any,
            !p.has_default, true};
  switch (p.rule) {
    case ParamRule::Positive:
    case ParamRule::PositiveVector: a.rule = ValueRule::Positive; break;
    case ParamRule::NonNegative: a.rule = ValueRule::NonNegative; break;
    case ParamRule::NonZeroVector: a.nonzero = true; break;
    case ParamRule::Any: break;
  }
  // Parameters that shape the emitted code itself cannot vary with time.
  const std::string name = p.name;
  if ((info.kind == PrimitiveKind::Menger && name == "level") ||
      (info.kind == PrimitiveKind::Plane && name == "normal") || info.kind == PrimitiveKind::Polygon)
    a.time_allowed = false;
  return a;
}

}  // namespace sdfc
