#include "check/point_file.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <limits>
#include <sstream>
#include <sys/stat.h>
#include <unistd.h>

namespace sdfc {

std::string resolveBesides(const std::string& sdf_path, const std::string& relative) {
  if (!relative.empty() && relative[0] == '/') return relative;
  const size_t slash = sdf_path.rfind('/');
  if (slash == std::string::npos) return relative;
  return sdf_path.substr(0, slash + 1) + relative;
}

namespace {

bool isBlank(char c) { return c == ' ' || c == '\t' || c == '\r'; }
bool isDelimiter(char c) { return c == ',' || c == ';'; }
bool isDigit(char c) { return c >= '0' && c <= '9'; }

// A decimal number as the language writes it (syntax/lexer.cpp), with an
// optional sign: digits with an optional fraction, or a fraction alone, then
// an optional exponent. Not hex (0x10), inf, nan or a dangling "1.5e".
bool isDecimalNumber(const std::string& s, size_t b, size_t e) {
  size_t i = b;
  if (i < e && (s[i] == '+' || s[i] == '-')) ++i;
  size_t digits = 0;
  while (i < e && isDigit(s[i])) ++i, ++digits;
  if (i < e && s[i] == '.') {
    ++i;
    while (i < e && isDigit(s[i])) ++i, ++digits;
  }
  if (digits == 0) return false;
  if (i < e && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    if (i < e && (s[i] == '+' || s[i] == '-')) ++i;
    size_t exponent = 0;
    while (i < e && isDigit(s[i])) ++i, ++exponent;
    if (exponent == 0) return false;
  }
  return i == e;
}

// Whether a field looks meant as a number ("1.5e", "0x10", "-.5q"): such a
// field in a first row makes it data, not a header.
bool startsLikeNumber(const std::string& s, size_t b, size_t e) {
  size_t i = b;
  if (i < e && (s[i] == '+' || s[i] == '-')) ++i;
  if (i < e && s[i] == '.') ++i;
  return i < e && isDigit(s[i]);
}

std::string formatNumber(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

struct Field {
  size_t begin, end;
};

// Reads the whole regular file at `path` (at most kMaxPointFileBytes) into
// `out.text`, or says why not in `out.unreadable_reason`.
bool readRegularFile(const std::string& path, PointFile& out) {
  // O_NONBLOCK: opening a FIFO for reading would wait for a writer.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    out.unreadable_reason = std::strerror(errno);
    return false;
  }
  struct stat st;
  std::string why;
  if (::fstat(fd, &st) != 0) why = std::strerror(errno);
  else if (S_ISDIR(st.st_mode)) why = "it is a directory";
  else if (!S_ISREG(st.st_mode)) why = "it is not a regular file (a FIFO, device or socket)";
  else if (static_cast<unsigned long long>(st.st_size) > kMaxPointFileBytes)
    why = std::to_string(st.st_size) + " bytes, at most " + std::to_string(kMaxPointFileBytes >> 20) + " MiB";
  std::string text;
  char buffer[1 << 16];
  while (why.empty()) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) why = std::strerror(errno);
    if (n <= 0) break;
    text.append(buffer, static_cast<size_t>(n));
    if (text.size() > kMaxPointFileBytes)  // grew while read
      why = "more than " + std::to_string(kMaxPointFileBytes >> 20) + " MiB";
  }
  ::close(fd);
  if (!why.empty()) {
    out.unreadable_reason = why;
    return false;
  }
  out.text = std::move(text);
  return true;
}

}  // namespace

PointFile readPointFile(const std::string& path) {
  PointFile out;
  if (!readRegularFile(path, out)) return out;
  out.readable = true;
  const std::string& text = out.text;
  constexpr double kFloatMax = std::numeric_limits<float>::max();
  bool seen_data = false;
  auto bad = [&](size_t begin, size_t end, std::string message) {
    if (out.errors.size() < kMaxPointFileErrors) out.errors.push_back({begin, end, std::move(message)});
    ++out.bad_rows;
  };
  size_t line_start = 0;
  std::vector<Field> fields;
  while (line_start < text.size()) {
    size_t stop = text.find('\n', line_start);
    if (stop == std::string::npos) stop = text.size();
    size_t i = line_start;
    line_start = stop + 1;
    while (stop > i && text[stop - 1] == '\r') --stop;
    while (i < stop && isBlank(text[i])) ++i;
    if (i == stop || text[i] == '#') continue;
    const size_t row_begin = i;
    size_t row_end = stop;
    while (row_end > row_begin && isBlank(text[row_end - 1])) --row_end;
    // Fields: between ',' or ';' (blanks around them trimmed), or, on a line
    // with neither, between runs of blanks.
    fields.clear();
    bool delimited = false;
    for (size_t k = row_begin; k < row_end; ++k) delimited = delimited || isDelimiter(text[k]);
    if (delimited) {
      size_t b = row_begin;
      for (;;) {
        size_t e = b;
        while (e < row_end && !isDelimiter(text[e])) ++e;
        size_t fb = b, fe = e;
        while (fb < fe && isBlank(text[fb])) ++fb;
        while (fe > fb && isBlank(text[fe - 1])) --fe;
        fields.push_back({fb, fe});
        if (e == row_end) break;
        b = e + 1;
      }
    } else {
      for (size_t b = row_begin; b < row_end;) {
        size_t e = b;
        while (e < row_end && !isBlank(text[e])) ++e;
        fields.push_back({b, e});
        b = e;
        while (b < row_end && isBlank(text[b])) ++b;
      }
    }
    const Field* wrong = nullptr;
    bool number_like = false;
    for (const Field& f : fields) {
      if (!wrong && !isDecimalNumber(text, f.begin, f.end)) wrong = &f;
      number_like = number_like || startsLikeNumber(text, f.begin, f.end);
    }
    const bool first = !seen_data;
    seen_data = true;
    if (wrong && first && !number_like) continue;  // a header such as "x,y,z"
    if (wrong) {
      if (wrong->begin == wrong->end) {
        // Point at the delimiter after the empty field (or before it at the end).
        const size_t at = wrong->begin < row_end ? wrong->begin : wrong->begin - 1;
        bad(at, at + 1, "empty field: every field between ',' or ';' must hold a number");
      } else {
        std::string message = "'" + text.substr(wrong->begin, wrong->end - wrong->begin) +
                              "' is not a decimal number";
        if (first)
          message += " (a first row is a header only when none of its fields starts like a number)";
        bad(wrong->begin, wrong->end, message);
      }
      continue;
    }
    if (fields.size() != 3 && fields.size() != 4) {
      bad(row_begin, row_end,
          "expected 3 or 4 numbers (x, y, z[, scale]), found " + std::to_string(fields.size()));
      continue;
    }
    double values[4];
    const Field* too_big = nullptr;
    for (size_t k = 0; k < fields.size(); ++k) {
      values[k] = std::strtod(text.c_str() + fields[k].begin, nullptr);
      if (!too_big && !(std::fabs(values[k]) <= kFloatMax)) too_big = &fields[k];
    }
    if (too_big) {
      // The same rule as numbers in the scene (checker.cpp, checkShaderValue).
      bad(too_big->begin, too_big->end,
          "'" + text.substr(too_big->begin, too_big->end - too_big->begin) +
              "' is beyond the range of the shader's float32 numbers (" + formatNumber(kFloatMax) + ")");
      continue;
    }
    PositionRow row;
    row.position = {values[0], values[1], values[2]};
    if (fields.size() == 4) row.scale = values[3];
    if (!(row.scale > 0)) {
      bad(fields[3].begin, fields[3].end, "scale must be positive, got " + formatNumber(row.scale));
      continue;
    }
    // The shader receives -position / scale and 1 / scale.
    const double largest = std::max({std::fabs(row.position.x), std::fabs(row.position.y), std::fabs(row.position.z), 1.0});
    if (largest / row.scale > kFloatMax) {
      bad(row_begin, row_end, "position / scale is beyond the range of the shader's float32 numbers (" +
                                  formatNumber(kFloatMax) + ")");
      continue;
    }
    out.rows.push_back(row);
  }
  if (out.bad_rows == 0) std::string().swap(out.text);
  return out;
}

}  // namespace sdfc
