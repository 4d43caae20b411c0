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

// A diagnostic made elsewhere (a parametric body's own list): an error
// counts as one, a warning is named and may be turned off here as any other.
Diagnostic& Diagnostics::add(Diagnostic d) {
  if (d.severity == Severity::Warning) {
    if (isSuppressed(d.range, d.name)) {
      ++suppressed_count_;
      scratch_ = {};
      return scratch_;
    }
    ++warning_count_;
  }
  if (d.severity == Severity::Error) ++error_count_;
  list_.push_back(std::move(d));
  return list_.back();
}

Diagnostic& Diagnostics::warning(SourceRange range, const char* name, std::string message) {
  if (isSuppressed(range, name)) {
    ++suppressed_count_;
    scratch_ = {};
    return scratch_;
  }
  ++warning_count_;
  list_.push_back({Severity::Warning, range, std::move(message), {}, name});
  return list_.back();
}

void Diagnostics::allowIn(SourceRange region, const std::string& name) {
  allowed_.push_back({region, name});
}

bool Diagnostics::isSuppressed(const SourceRange& range, const std::string& name) const {
  if (disabled_.count(name)) return true;
  for (const Allowed& a : allowed_)
    if (a.name == name && (a.region.file == nullptr ||
                           (range.file == a.region.file && range.begin >= a.region.begin &&
                            range.begin < a.region.end)))
      return true;
  return false;
}

namespace {
// Source lines longer than this many bytes are echoed as a window of about
// this many characters, kEchoBefore of them before the caret.
constexpr size_t kEchoWidth = 160;
constexpr size_t kEchoBefore = 60;
constexpr std::string_view kEllipsis = "...";

bool isContinuation(char c) { return (static_cast<unsigned char>(c) & 0xC0) == 0x80; }
// The byte offset `count` characters before / after `at` in `text`.
size_t backCodePoints(std::string_view text, size_t at, size_t count) {
  while (at > 0 && count > 0) {
    --at;
    while (at > 0 && isContinuation(text[at])) --at;
    --count;
  }
  return at;
}
size_t forwardCodePoints(std::string_view text, size_t at, size_t count) {
  while (at < text.size() && count > 0) {
    ++at;
    while (at < text.size() && isContinuation(text[at])) ++at;
    --count;
  }
  return at;
}

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
    if (!d.name.empty()) out << " [-W" << d.name << "]";
    out << "\n";
    const std::string_view line_text = file->lineText(line);
    const size_t line_begin = file->lineStart(line);
    const size_t caret = std::min(d.range.begin - std::min(d.range.begin, line_begin), line_text.size());
    // A long line is echoed as a window around the caret: one diagnostic per
    // character of a 100,000-character line must not print the line each time.
    size_t from = 0, to = line_text.size();
    if (line_text.size() > kEchoWidth) {
      from = backCodePoints(line_text, caret, kEchoBefore);
      to = forwardCodePoints(line_text, from, kEchoWidth - 2 * kEllipsis.size());
    }
    const std::string_view text = line_text.substr(from, to - from);
    const std::string_view lead = from > 0 ? kEllipsis : std::string_view();
    out << lead << text << (to < line_text.size() ? kEllipsis : std::string_view()) << "\n";
    // The caret spans the range on its first line; tabs are kept so it
    // lines up, and each character (not byte) before it is one column.
    const size_t before = caret - from;
    std::string marker(lead.size(), ' ');
    for (size_t i = 0; i < before; ++i) {
      if ((static_cast<unsigned char>(text[i]) & 0xC0) == 0x80) continue;
      marker += text[i] == '\t' ? '\t' : ' ';
    }
    const size_t range_end = std::min(d.range.end, line_begin + to);
    size_t width = range_end > d.range.begin && before < text.size()
                       ? codePointCount(text.substr(before, range_end - line_begin - from - before))
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

std::vector<const Diagnostic*> Diagnostics::sorted() const {
  std::vector<const Diagnostic*> out;
  for (const Diagnostic& d : list_) out.push_back(&d);
  std::stable_sort(out.begin(), out.end(), [](const Diagnostic* a, const Diagnostic* b) {
    return a->range.begin < b->range.begin;
  });
  return out;
}

namespace {
// The diagnostics shown under an error limit: everything up to and including
// the limit-th error (its notes too), and the note that says what was left.
struct Shown {
  std::vector<const Diagnostic*> list;
  std::string left_out;  // "" when nothing was
};

Shown underLimit(const std::vector<const Diagnostic*>& all, int error_limit) {
  Shown out;
  int errors = 0;
  size_t i = 0;
  for (; i < all.size(); ++i) {
    if (error_limit > 0 && errors == error_limit) break;
    if (all[i]->severity == Severity::Error) ++errors;
    out.list.push_back(all[i]);
  }
  int more_errors = 0, more_warnings = 0;
  for (; i < all.size(); ++i) (all[i]->severity == Severity::Error ? more_errors : more_warnings)++;
  if (more_errors + more_warnings == 0) return out;
  auto count = [](int n, const char* what) {
    return std::to_string(n) + " more " + what + (n == 1 ? "" : "s");
  };
  out.left_out = "stopped after " + std::to_string(error_limit) + " errors; " +
                 (more_errors ? count(more_errors, "error") : "") +
                 (more_errors && more_warnings ? " and " : "") +
                 (more_warnings ? count(more_warnings, "warning") : "") +
                 " not shown (--error-limit 0 shows them all)";
  return out;
}
}  // namespace

std::string Diagnostics::format(bool color, int error_limit) const {
  const Shown shown = underLimit(sorted(), error_limit);
  std::ostringstream out;
  for (const Diagnostic* d : shown.list) appendOne(out, *d, color);
  if (!shown.left_out.empty()) appendOne(out, {Severity::Note, {}, shown.left_out, {}, ""}, color);
  return out.str();
}

std::string Diagnostics::formatJson(int error_limit) const {
  const Shown shown = underLimit(sorted(), error_limit);
  std::vector<const Diagnostic*> list = shown.list;
  const Diagnostic note{Severity::Note, {}, shown.left_out, {}, ""};
  if (!shown.left_out.empty()) list.push_back(&note);
  std::ostringstream out;
  out << "[";
  bool first = true;
  // "file", "line", "column", "end_column", "severity" of `d` (or of a note).
  auto where = [&](const Diagnostic& d) {
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
        << ",\"end_column\":" << end_col << ",\"severity\":\"" << severityName(d.severity) << "\"";
  };
  for (const Diagnostic* diagnostic : list) {
    const Diagnostic& d = *diagnostic;
    if (!first) out << ",";
    first = false;
    where(d);
    if (!d.name.empty()) out << ",\"name\":\"" << jsonEscape(d.name) << "\"";
    out << ",\"message\":\"" << jsonEscape(d.message) << "\"";
    // The notes the text form prints under it (an import cycle's chain, where
    // a definition's mistake arose): they were left out.
    if (!d.notes.empty()) {
      out << ",\"notes\":[";
      for (size_t i = 0; i < d.notes.size(); ++i) {
        if (i) out << ",";
        where(d.notes[i]);
        out << ",\"message\":\"" << jsonEscape(d.notes[i].message) << "\"}";
      }
      out << "]";
    }
    out << "}";
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
