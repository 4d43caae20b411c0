// What must hold after checkSource on any input, shared by the fuzz target
// and tests/grammar_test.cpp: diagnostics point inside the file, and a scene
// that checked without errors carries only finite numbers (the emitter
// prints them into GLSL, where inf and nan are not literals).
#pragma once
#include <cmath>
#include <string>
#include <unordered_set>

#include "driver/compile.h"

namespace sdfc::fuzz {

inline std::string rangeProblem(const Diagnostic& d, const SourceFile* source) {
  if (d.range.file) {
    // Another file is one the scene imports (import "parts.sdf"): its own text bounds the range.
    if (d.range.file != source && d.range.file->path == source->path)
      return "a diagnostic points into another copy of the file: " + d.message;
    if (d.range.begin > d.range.end || d.range.end > d.range.file->text.size())
      return "a diagnostic range is outside the file: " + d.message;
  }
  for (const Diagnostic& n : d.notes)
    if (std::string p = rangeProblem(n, source); !p.empty()) return p;
  return "";
}

class FiniteScan {
 public:
  std::string problem;

  void number(double v, const char* what) {
    if (problem.empty() && !std::isfinite(v)) problem = std::string("non-finite ") + what + " in a checked scene";
  }
  void vec(const glm::dvec3& v, const char* what) {
    for (int i = 0; i < 3; ++i) number(v[i], what);
  }
  void scalar(const ir::Scalar& s, const char* what) { number(s.value, what); }
  void vec(const ir::Vec3& v, const char* what) {
    scalar(v.x, what);
    scalar(v.y, what);
    scalar(v.z, what);
  }
  void node(const ir::Node& n) {
    if (!seen_.insert(&n).second) return;  // shared definitions: once
    for (const ir::Scalar& s : n.args) scalar(s, "primitive parameter");
    scalar(n.smooth, "smooth radius");
    vec(n.vec, "operator vector");
    scalar(n.amount, "operator amount");
    for (int c = 0; c < 3; ++c) vec(glm::dvec3(n.linear[c]), "affine matrix");
    vec(n.offset, "affine offset");
    number(n.scale, "affine scale");
    for (const ir::NodeRef& c : n.children) node(*c);
  }
  void scene(const ir::Scene& s) {
    if (s.root) node(*s.root);
    for (const ir::Material& m : s.materials) {
      vec(m.albedo, "material colour");
      vec(m.emission, "material emission");
      number(m.ior, "material ior");
      number(m.roughness, "material roughness");
    }
    vec(s.camera.position, "camera position");
    vec(s.camera.target, "camera target");
    vec(s.camera.up, "camera up");
    number(s.camera.fov_degrees, "camera fov");
    number(s.camera.aperture, "camera aperture");
    number(s.camera.focus_distance, "camera focus");
    vec(s.sky.top, "sky colour");
    vec(s.sky.bottom, "sky colour");
    if (s.sun) {
      vec(s.sun->direction, "sun direction");
      number(s.sun->angle_degrees, "sun angle");
      vec(s.sun->radiance, "sun radiance");
    }
    for (const ir::SphereLight& l : s.lights) {
      vec(l.position, "light position");
      number(l.radius, "light radius");
      vec(l.radiance, "light radiance");
    }
  }

 private:
  std::unordered_set<const ir::Node*> seen_;
};

// "" when every invariant holds, else what broke.
inline std::string violatedInvariant(const CompiledScene& compiled, const Diagnostics& diags,
                                     bool check_finite) {
  for (const Diagnostic& d : diags.all())
    if (std::string p = rangeProblem(d, compiled.source.get()); !p.empty()) return p;
  if (diags.hasErrors()) return "";
  if (!compiled.ok) return "no errors, yet no scene";
  if (check_finite) {
    FiniteScan scan;
    scan.scene(compiled.scene);
    return scan.problem;
  }
  return "";
}

}  // namespace sdfc::fuzz
