// Positions read at compile time for instances(positions: file("...")):
// one row per instance, "x, y, z" or "x, y, z, scale", separated by commas,
// semicolons or white space; blank lines and lines starting with '#' are
// skipped, and so is a first row that holds no number (a header).
#pragma once
#include <glm/glm.hpp>
#include <string>
#include <vector>

namespace sdfc {

struct PositionRow {
  glm::dvec3 position{0};
  double scale = 1;
};

struct PointFile {
  std::vector<PositionRow> rows;
  bool readable = false;
  // "line N: ..." per bad row (at most kMaxPointFileErrors), and how many in all.
  std::vector<std::string> errors;
  size_t bad_rows = 0;
};

constexpr size_t kMaxPointFileErrors = 5;

PointFile readPointFile(const std::string& path);
// A path in the .sdf relative to the directory of the .sdf file itself.
std::string resolveBesides(const std::string& sdf_path, const std::string& relative);

}  // namespace sdfc
