#include "lsp/catalogue.h"

#include <cstdio>

#include "check/builtins.h"
#include "check/checker.h"
#include "ir/scene.h"
#include "ir/expr.h"
#include "shapes/primitives.h"

namespace sdfc::lsp {
namespace {

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

ParamDoc materialParam() {
  ParamDoc p;
  p.name = "material";
  p.type = "material";
  p.fallback = "inherited";
  p.time_allowed = false;
  return p;
}

std::string vec(const glm::dvec3& v) { return "[" + number(v.x) + ", " + number(v.y) + ", " + number(v.z) + "]"; }

// Defaults of the settings are the IR's own initial values, and limits are
// the checker's constants: the editor quotes them rather than a copy.
void settingFacts(const std::string& callee, ParamDoc& d) {
  static const ir::Camera camera;
  static const ir::RenderSettings render;
  static const ir::Sky sky;
  static const ir::Sun sun;
  static const ir::SphereLight light;
  const std::string key = callee + "." + d.name;
  if (key == "camera.position") d.fallback = vec(camera.position);
  if (key == "camera.target") d.fallback = vec(camera.target);
  if (key == "camera.up") d.fallback = vec(camera.up);
  if (key == "camera.fov") d.fallback = number(camera.fov_degrees);
  if (key == "camera.aperture") d.fallback = number(camera.aperture);
  if (key == "render.size") {
    d.fallback = "[" + number(render.width) + ", " + number(render.height) + "]";
    d.rule = "whole, 1 to " + std::to_string(kMaxImageSide) + " per side";
  }
  if (key == "render.spp") {
    d.fallback = number(render.spp);
    d.rule = "whole, 1 to " + std::to_string(kMaxSamples);
  }
  if (key == "render.bounces") {
    d.fallback = number(render.bounces);
    d.rule = "whole, 0 to " + std::to_string(kMaxBounces);
  }
  if (key == "render.light_samples") {
    d.fallback = number(render.light_samples);
    d.rule = "whole, 0 to 16";
  }
  if (key == "sky.top" || key == "sky.color") d.fallback = vec(sky.top);
  if (key == "sky.bottom") d.fallback = vec(sky.bottom);
  if (key == "sky.map") d.type = "string naming an EXR or .hdr image (equirectangular, 2:1, y up)";
  if (key == "sky.rotation") d.fallback = number(sky.rotation_degrees) + " (degrees about y)";
  if (key == "sky.strength") d.fallback = number(sky.strength);
  if (key == "sun.direction") d.fallback = vec(sun.direction);
  if (key == "sun.angle") d.fallback = number(sun.angle_degrees);
  if (key == "light.radius") d.fallback = number(light.radius);
  if (key == "repeat.count") d.rule = "whole, 0 (infinite) to " + std::to_string(kMaxRepeatCount);
}

std::vector<CalleeDoc> build() {
  std::vector<CalleeDoc> out;
  for (const PrimitiveInfo& info : primitiveCatalogue()) {
    CalleeDoc c{info.name, CalleeKind::Primitive, info.summary, {}, info.exact};
    for (const ParamSpec& p : info.params) {
      const ArgSpec a = argSpecOf(p, info);
      ParamDoc d;
      d.name = p.name;
      d.type = p.type == ParamType::Vector    ? "vector"
               : p.type == ParamType::Vector2 ? "2-vector"
               : p.type == ParamType::Points  ? "list of [x, y]"
                                              : "number";
      switch (p.rule) {
        case ParamRule::Positive: d.rule = "> 0"; break;
        case ParamRule::PositiveVector: d.rule = "each > 0"; break;
        case ParamRule::NonNegative: d.rule = ">= 0"; break;
        case ParamRule::NonZeroVector: d.rule = "non-zero"; break;
        case ParamRule::Any: break;
      }
      if (info.kind == PrimitiveKind::Menger && d.name == "level")
        d.rule = "whole, 0 to " + std::to_string(kMaxMengerLevel);
      if (p.has_default)
        d.fallback = p.type == ParamType::Vector2 ? "[" + number(p.default_value.x) + ", " + number(p.default_value.y) + "]"
                     : p.type == ParamType::Vector
                         ? "[" + number(p.default_value.x) + ", " + number(p.default_value.y) + ", " +
                               number(p.default_value.z) + "]"
                         : number(p.default_value.x);
      d.required = !p.has_default;
      d.time_allowed = a.time_allowed;
      c.params.push_back(d);
    }
    c.params.push_back(materialParam());
    out.push_back(std::move(c));
  }
  for (const BuiltinSignature& s : builtinSignatures()) {
    const CalleeKind kind = s.category == BuiltinCategory::Operator   ? CalleeKind::Operator
                            : s.category == BuiltinCategory::Material ? CalleeKind::Material
                            : s.category == BuiltinCategory::Field    ? CalleeKind::Field
                                                                      : CalleeKind::Setting;
    CalleeDoc c{s.name, kind, s.summary, {}, true};
    for (const ArgSpec& a : s.args) {
      ParamDoc d;
      d.name = a.name;
      d.type = a.type == ArgType::Number    ? "number"
               : a.type == ArgType::Vector3 ? "vector"
               : a.type == ArgType::Vector2 ? "2-vector"
               : a.type == ArgType::Colour  ? "colour or colour field"
                                            : "number or vector";
      d.rule = a.rule == ValueRule::Positive ? "> 0" : a.rule == ValueRule::NonNegative ? ">= 0" : "";
      if (a.nonzero) d.rule = "non-zero";
      d.required = a.required;
      d.time_allowed = a.time_allowed;
      settingFacts(s.name, d);
      c.params.push_back(d);
    }
    if (kind == CalleeKind::Operator) c.params.push_back(materialParam());
    out.push_back(std::move(c));
  }
  for (const std::string& f : ir::mathFunctionNames()) {
    CalleeDoc c{f, CalleeKind::Math, "math function", {}, true};
    const int arity = ir::mathFunctionArity(f);
    for (int i = 0; i < arity; ++i) {
      ParamDoc d;
      d.name = arity == 1 ? "x" : std::string(1, "xyz"[i % 3]);
      d.type = "number";
      d.required = true;
      c.params.push_back(d);
    }
    out.push_back(std::move(c));
  }
  out.push_back({"scene", CalleeKind::Scene, "the shapes to render; exactly one per file", {}, true});
  return out;
}

}  // namespace

std::string ParamDoc::label() const {
  std::string s = name + ": " + type;
  if (!fallback.empty()) s += " = " + fallback;
  return s;
}

std::string CalleeDoc::signature() const {
  std::string s = name + "(";
  for (size_t i = 0; i < params.size(); ++i) s += (i ? ", " : "") + params[i].label();
  s += ")";
  if (kind == CalleeKind::Operator || kind == CalleeKind::Scene) s += " { ... }";
  return s;
}

const char* kindName(CalleeKind kind) {
  switch (kind) {
    case CalleeKind::Primitive: return "primitive";
    case CalleeKind::Definition: return "definition";
    case CalleeKind::Operator: return "operator";
    case CalleeKind::Material: return "material";
    case CalleeKind::Field: return "colour field";
    case CalleeKind::Setting: return "setting";
    case CalleeKind::Math: return "math function";
    case CalleeKind::Scene: return "scene";
  }
  return "";
}

std::string CalleeDoc::markdown() const {
  std::string s = "```sdf\n" + signature() + "\n```\n" + kindName(kind) + ": " + summary + "\n";
  if (kind == CalleeKind::Primitive)
    s += exact ? "\nExact Euclidean distance.\n" : "\nA distance bound, not an exact distance.\n";
  if (!params.empty()) s += "\n";
  for (const ParamDoc& p : params) {
    s += "- `" + p.name + "`: " + p.type;
    if (!p.rule.empty()) s += ", " + p.rule;
    s += p.required ? ", required" : (p.fallback.empty() ? ", optional" : ", default " + p.fallback);
    if (!p.time_allowed) s += ", constant (no `time`)";
    s += "\n";
  }
  return s;
}

const std::vector<CalleeDoc>& callees() {
  static const std::vector<CalleeDoc> all = build();
  return all;
}

const CalleeDoc* findCallee(const std::string& name) {
  for (const CalleeDoc& c : callees())
    if (c.name == name) return &c;
  return nullptr;
}

}  // namespace sdfc::lsp
