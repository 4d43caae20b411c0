// Diagnostics as the editor shows them: the checker's own messages and
// ranges (the same as `sdfc check`), notes as related information.
#include "lsp/features.h"

namespace sdfc::lsp {
namespace {

json rangeOf(const Analysis& a, const SourceRange& r) {
  if (!r.file) return a.lines.rangeOf(0, 0);  // whole-file problems point at the start
  return a.lines.rangeOf(r.begin, std::max(r.begin, r.end));
}

// A diagnostic inside another file (a bad row of a CSV the scene reads) is
// shown at its first note in the document, the file(...) string, with the
// other file's path, line and column in front of its message.
Diagnostic inDocument(const Analysis& a, const Diagnostic& d) {
  if (!d.range.file || d.range.file == &a.source()) return d;
  Diagnostic shown = d;
  auto [line, col] = d.range.file->lineColumn(d.range.begin);
  shown.message = d.range.file->path + ":" + std::to_string(line) + ":" + std::to_string(col) + ": " + d.message;
  shown.range = {};
  shown.notes.clear();
  for (const Diagnostic& n : d.notes) {
    if (n.range.file != &a.source()) continue;
    if (!shown.range.file) shown.range = n.range;
    else shown.notes.push_back(n);
  }
  return shown;
}

}  // namespace

json publishDiagnostics(const Analysis& a) {
  json list = json::array();
  for (const Diagnostic& original : a.diagnostics.all()) {
    const Diagnostic d = inDocument(a, original);
    json item = {{"range", rangeOf(a, d.range)},
                 {"severity", d.severity == Severity::Error ? 1 : d.severity == Severity::Warning ? 2 : 3},
                 {"source", "sdfc"},
                 {"message", d.message}};
    if (!d.notes.empty()) {
      json related = json::array();
      for (const Diagnostic& n : d.notes)
        related.push_back({{"location", {{"uri", a.uri}, {"range", rangeOf(a, n.range)}}},
                           {"message", n.message}});
      item["relatedInformation"] = related;
    }
    list.push_back(std::move(item));
  }
  return {{"uri", a.uri}, {"version", a.version}, {"diagnostics", list}};
}

}  // namespace sdfc::lsp
