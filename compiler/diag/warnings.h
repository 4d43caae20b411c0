// The names of sdfc's warnings: each is printed as [-Wname] after its
// message and turned off with -Wno-name on the command line or with
// `// sdfc: allow(name)` in a scene (docs/language.md, "Warnings").
#pragma once
#include <string>
#include <vector>

namespace sdfc {

struct WarningInfo {
  const char* name;
  const char* summary;  // for --help and docs/language.md
};

inline constexpr WarningInfo kWarnings[] = {
    {"bound", "a shape's distance is a bound, not exact (smooth CSG, morph, non-uniform scale, "
              "spindle torus): marching takes smaller steps near it"},
    {"unused", "a definition or a material that nothing uses"},
    {"time-range", "a value that depends on 'time' leaves its valid range at some times"},
    {"energy", "an albedo or tint above 1 reflects more light than arrives"},
    {"repeat-reach", "a repeated shape wide enough that many cells or sectors are evaluated, or more than are checked"},
    {"bend-fold", "a 'bend' strong enough to fold space inside the shape (it shows twice there)"},
    {"subtract-nothing", "'subtract' with one shape"},
    {"setting-again", "a setting given twice (the last one wins)"},
    {"mesh-open", "a mesh(file: ...) with boundary edges: its winding number decides inside, which "
                  "is a guess near the holes"},
    {"mesh-degenerate", "a mesh(file: ...) with triangles of no area (they are dropped)"},
    {"mesh-inward", "a closed mesh(file: ...) that faces inward (negative volume): it is turned to face outward"},
    {"unknown-warning", "a warning name in `// sdfc: allow(...)` that sdfc does not know"},
};

inline bool isWarningName(const std::string& name) {
  for (const WarningInfo& w : kWarnings)
    if (name == w.name) return true;
  return false;
}

inline std::vector<std::string> warningNames() {
  std::vector<std::string> out;
  for (const WarningInfo& w : kWarnings) out.push_back(w.name);
  return out;
}

}  // namespace sdfc
