#include "check/builtins.h"

#include "ir/expr.h"

namespace sdfc {
namespace {

constexpr bool kRequired = true, kOptional = false, kTime = true, kConstant = false;

ArgSpec colour(const char* name) {
  return {name, ArgType::Vector3, ValueRule::NonNegative, kOptional, kConstant};
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
      // Materials.
      {"diffuse", BuiltinCategory::Material, {colour("albedo")}, "Lambertian"},
      {"mirror", BuiltinCategory::Material, {colour("tint")}, "perfect specular reflection"},
      {"glass", BuiltinCategory::Material,
       {{"ior", ArgType::Number, ValueRule::Positive, kOptional, kConstant}, colour("tint")},
       "dielectric with Fresnel reflection and refraction"},
      {"emissive", BuiltinCategory::Material,
       {colour("color"), {"strength", ArgType::Number, ValueRule::NonNegative, kOptional, kConstant}},
       "emits color * strength"},
      {"metal", BuiltinCategory::Material,
       {colour("albedo"), {"roughness", ArgType::Number, ValueRule::NonNegative, kOptional, kConstant}},
       "GGX microfacet conductor"},
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
      {"sky", BuiltinCategory::Setting, {colour("color"), colour("top"), colour("bottom")},
       "constant or vertical-gradient environment"},
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
  ArgSpec a{p.name, p.type == ParamType::Vector ? ArgType::Vector3 : ArgType::Number, ValueRule::Any,
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
      (info.kind == PrimitiveKind::Plane && name == "normal"))
    a.time_allowed = false;
  return a;
}

}  // namespace sdfc
