#include "diag/diagnostics.h"

#include <algorithm>
#include <sstream>

namespace sdfc {

Diagnostic& Diagnostics::error(SourceRange range, std::string message) {
  ++error_count_;
  list_.push_back({Severity::Error, range, std::move(message), {}});
  return list_.back();
}

const SourceFile& Diagnostics::keep(std::unique_ptr<SourceFile> file) {
  kept_.push_back(std::move(file));
  return *kept_.back();
}

Diagnostic& Diagnostics::warning(SourceRange range, std::string message) {
  list_.push_back({Severity::Warning, range, std::move(message), {}});
  return list_.back();
}

Diagnostic& Diagnostics::add(Diagnostic d) {
  if (d.severity == Severity::Error) ++error_count_;
  list_.push_back(std::move(d));
  return list_.back();
}

namespace {
const char* severityName(Severity s) {
  switch (s) {
    case Severity::Error: return "error";
    case Severity::Warning: return "warning";
    case Severity::Note: return "note";
  }
  return "error";
}
const char* severityColor(Severity s) {
  switch (s) {
    case Severity::Error: return "\033[1;31m";
    case Severity::Warning: return "\033[1;35m";
    case Severity::Note: return "\033[1;36m";
  }
  return "";
}

void appendOne(std::ostringstream& out, const Diagnostic& d, bool color) {
  const SourceFile* file = d.range.file;
  if (file) {
    auto [line, col] = file->lineColumn(d.range.begin);
    if (color) out << "\033[1m";
    out << file->path << ":" << line << ":" << col << ": ";
    if (color) out << severityColor(d.severity);
    out << severityName(d.severity) << ": ";
    if (color) out << "\033[0;1m";
    out << d.message;
    if (color) out << "\033[0m";
    out << "\n";
    const std::string_view text = file->lineText(line);
    out << text << "\n";
    // The caret spans the range on its first line; tabs are kept so it
    // lines up, and each character (not byte) before it is one column.
    const size_t line_begin = file->lineStart(line);
    const size_t before = std::min(d.range.begin - std::min(d.range.begin, line_begin), text.size());
    std::string marker;
    for (size_t i = 0; i < before; ++i) {
      if ((static_cast<unsigned char>(text[i]) & 0xC0) == 0x80) continue;
      marker += text[i] == '\t' ? '\t' : ' ';
    }
    const size_t range_end = std::min(d.range.end, line_begin + text.size());
    size_t width = range_end > d.range.begin
                       ? codePointCount(text.substr(before, range_end - line_begin - before))
                       : 1;
    width = std::max<size_t>(width, 1);
    marker += '^';
    marker += std::string(width - 1, '~');
    if (color) out << "\033[1;32m";
    out << marker;
    if (color) out << "\033[0m";
    out << "\n";
  } else {
    out << "sdfc: " << severityName(d.severity) << ": " << d.message << "\n";
  }
  for (const Diagnostic& note : d.notes) appendOne(out, note, color);
}

std::string jsonEscape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out += buf;
        } else {
          out += c;
        }
    }
  }
  return out;
}
}  // namespace

std::string formatDiagnostic(const Diagnostic& d, bool color) {
  std::ostringstream out;
  appendOne(out, d, color);
  return out.str();
}

std::string Diagnostics::format(bool color) const {
  std::vector<const Diagnostic*> sorted;
  for (const Diagnostic& d : list_) sorted.push_back(&d);
  std::stable_sort(sorted.begin(), sorted.end(), [](const Diagnostic* a, const Diagnostic* b) {
    return a->range.begin < b->range.begin;
  });
  std::ostringstream out;
  for (const Diagnostic* d : sorted) appendOne(out, *d, color);
  return out.str();
}

std::string Diagnostics::formatJson() const {
  std::ostringstream out;
  out << "[";
  bool first = true;
  for (const Diagnostic& d : list_) {
    if (!first) out << ",";
    first = false;
    int line = 0, col = 0, end_col = 0;
    std::string path;
    if (d.range.file) {
      std::tie(line, col) = d.range.file->lineColumn(d.range.begin);
      const std::string_view text = d.range.file->text;
      const size_t begin = std::min(d.range.begin, text.size());
      const size_t end = std::max(begin, std::min(d.range.end, text.size()));
      end_col = col + static_cast<int>(codePointCount(text.substr(begin, end - begin)));
      path = d.range.file->path;
    }
    out << "{\"file\":\"" << jsonEscape(path) << "\",\"line\":" << line << ",\"column\":" << col
        << ",\"end_column\":" << end_col << ",\"severity\":\"" << severityName(d.severity)
        << "\",\"message\":\"" << jsonEscape(d.message) << "\"}";
  }
  out << "]\n";
  return out.str();
}

size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] != b[j - 1])});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

std::string nearestName(const std::string& name, const std::vector<std::string>& candidates) {
  std::string best;
  size_t best_distance = std::max<size_t>(2, name.size() / 3) + 1;
  for (const std::string& c : candidates) {
    const size_t d = editDistance(name, c);
    if (d < best_distance) {
      best_distance = d;
      best = c;
    }
  }
  return best;
}

}  // namespace sdfc
