// Positions read at compile time for instances(positions: file("...")):
// one row per instance, "x, y, z" or "x, y, z, scale". docs/language.md has
// the rules; in short: fields are separated by ',' or ';' (an empty field is
// an error) or, on a line with neither, by spaces and tabs; every field is a
// decimal number as the language writes them (an optional sign), within
// float32's range; blank lines and lines starting with '#' are skipped, and a
// first row none of whose fields starts like a number is a header.
#pragma once
#include <glm/glm.hpp>
#include <string>
#include <vector>

namespace sdfc {

struct PositionRow {
  glm::dvec3 position{0};
  double scale = 1;
};

// A bad field or row: its byte range in the file's text.
struct PointFileError {
  size_t begin = 0, end = 0;
  std::string message;
};

struct PointFile {
  std::vector<PositionRow> rows;
  bool readable = false;
  std::string unreadable_reason;  // when !readable: "it is a directory", ...
  // The first kMaxPointFileErrors bad rows, and how many in all; `text` (the
  // file's content) is kept only when there are some, for their diagnostics.
  std::vector<PointFileError> errors;
  size_t bad_rows = 0;
  std::string text;
};

constexpr size_t kMaxPointFileErrors = 5;
// Far more than the largest instance set a render can hold (docs/language.md):
// a bigger file is refused before it is read, and so is anything that is
// not a regular file (a FIFO would block, /dev/zero never ends).
constexpr size_t kMaxPointFileBytes = size_t(256) << 20;

PointFile readPointFile(const std::string& path);
// A path in the .sdf relative to the directory of the .sdf file itself.
std::string resolveBesides(const std::string& sdf_path, const std::string& relative);

}  // namespace sdfc
