#include "check/other_spellings.h"

#include <algorithm>
#include <cctype>
#include <utility>

namespace sdfc {

std::string otherToolSpelling(const std::string& name) {
  // Compared without case and without '_', so smoothUnion, smooth_union and
  // opSmoothUnion all match.
  std::string key;
  for (char c : name)
    if (c != '_') key += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (key.rfind("op", 0) == 0 && key.size() > 2) key = key.substr(2);
  if (key.rfind("sd", 0) == 0 && key.size() > 2) key = key.substr(2);
  static const std::pair<const char*, const char*> table[] = {
      {"smoothunion", "union(smooth: k) { ... }"},
      {"smoothintersection", "intersect(smooth: k) { ... }"},
      {"smoothintersect", "intersect(smooth: k) { ... }"},
      {"smoothdifference", "subtract(smooth: k) { ... }"},
      {"smoothsubtraction", "subtract(smooth: k) { ... }"},
      {"smoothsubtract", "subtract(smooth: k) { ... }"},
      {"blend", "union(smooth: k) { ... }"},
      {"difference", "subtract { ... }"},
      {"subtraction", "subtract { ... }"},
      {"intersection", "intersect { ... }"},
      {"cube", "box(size: [s, s, s])"},
      {"roundedbox", "box(size: ..., rounding: r)"},
      {"roundbox", "box(size: ..., rounding: r)"},
      {"cappedcylinder", "cylinder(radius: r, height: h)"},
      {"move", "translate(offset) { ... }"},
      {"translated", "translate(offset) { ... }"},
      {"rotated", "rotate(axis: ..., degrees: ...) { ... }"},
      {"scaled", "scale(factor) { ... }"},
      {"mirror", "reflect(normal: ...) { ... }"},
      {"repetition", "repeat(cell: ...) { ... }"},
      {"rep", "repeat(cell: ...) { ... }"},
  };
  auto it = std::find_if(std::begin(table), std::end(table),
                         [&](const auto& entry) { return key == entry.first; });
  return it == std::end(table) ? "" : it->second;
}

}  // namespace sdfc
