#include "check/point_file.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace sdfc {

std::string resolveBesides(const std::string& sdf_path, const std::string& relative) {
  if (!relative.empty() && relative[0] == '/') return relative;
  const size_t slash = sdf_path.rfind('/');
  if (slash == std::string::npos) return relative;
  return sdf_path.substr(0, slash + 1) + relative;
}

namespace {

bool isSeparator(char c) { return c == ',' || c == ';' || c == ' ' || c == '\t' || c == '\r'; }

}  // namespace

PointFile readPointFile(const std::string& path) {
  PointFile out;
  std::ifstream in(path, std::ios::binary);
  if (!in) return out;
  out.readable = true;
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  size_t line_start = 0;
  int line = 0;
  bool seen_data = false;
  auto bad = [&](const std::string& message) {
    if (out.errors.size() < kMaxPointFileErrors)
      out.errors.push_back("line " + std::to_string(line) + ": " + message);
    ++out.bad_rows;
  };
  while (line_start < text.size()) {
    size_t end = text.find('\n', line_start);
    if (end == std::string::npos) end = text.size();
    ++line;
    size_t i = line_start;
    const size_t stop = end;
    line_start = end + 1;
    while (i < stop && isSeparator(text[i])) ++i;
    if (i == stop || text[i] == '#') continue;
    double values[5];
    int count = 0;
    bool numeric = true;
    std::string junk;
    while (i < stop) {
      const char* begin = text.c_str() + i;
      char* after = nullptr;
      errno = 0;
      const double v = std::strtod(begin, &after);
      const size_t used = static_cast<size_t>(after - begin);
      if (used == 0 || (i + used < stop && !isSeparator(text[i + used]))) {
        size_t j = i;
        while (j < stop && !isSeparator(text[j])) ++j;
        junk = text.substr(i, j - i);
        numeric = false;
        break;
      }
      if (count < 5) values[count] = v;
      ++count;
      i += used;
      while (i < stop && isSeparator(text[i])) ++i;
    }
    if (!numeric) {
      if (!seen_data && count == 0) {  // a header such as "x,y,z"
        seen_data = true;
        continue;
      }
      bad("'" + junk + "' is not a number");
      continue;
    }
    seen_data = true;
    if (count != 3 && count != 4) {
      bad("expected 3 or 4 numbers (x, y, z[, scale]), found " + std::to_string(count));
      continue;
    }
    PositionRow row;
    row.position = {values[0], values[1], values[2]};
    if (count == 4) row.scale = values[3];
    if (!std::isfinite(row.position.x + row.position.y + row.position.z + row.scale)) {
      bad("numbers must be finite");
      continue;
    }
    if (!(row.scale > 0)) {
      std::ostringstream s;
      s << "scale must be positive, got " << row.scale;
      bad(s.str());
      continue;
    }
    out.rows.push_back(row);
  }
  return out;
}

}  // namespace sdfc
