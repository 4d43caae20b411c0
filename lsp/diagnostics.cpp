// Diagnostics as the editor shows them: the checker's own messages and
// ranges (the same as `sdfc check`), notes as related information.
#include "lsp/features.h"

namespace sdfc::lsp {
namespace {

json rangeOf(const Analysis& a, const SourceRange& r) {
  if (!r.file) return a.lines.rangeOf(0, 0);  // whole-file problems point at the start
  return a.lines.rangeOf(r.begin, std::max(r.begin, r.end));
}

// A diagnostic inside another file that a note ties to this document (a bad
// row of a CSV the scene reads) is shown at that note, the file(...) string,
// with the other file's path, line and column in front of its message.
bool hasNoteHere(const Analysis& a, const Diagnostic& d) {
  for (const Diagnostic& n : d.notes)
    if (n.range.file == &a.source()) return true;
  return false;
}
Diagnostic atItsNote(const Analysis& a, const Diagnostic& d) {
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

// Any other problem inside an imported file is shown on this file's first
// import, named after that file, with its own place as related information.
SourceRange firstImport(const Analysis& a) {
  for (const ast::Statement& s : a.tree.statements)
    if (s.is_import) return s.import_path_range;
  return {};
}

}  // namespace

json publishDiagnostics(const Analysis& a) {
  json list = json::array();
  for (const Diagnostic& original : a.diagnostics.all()) {
    const bool other_file = original.range.file && original.range.file != &a.source();
    const bool tied_here = other_file && hasNoteHere(a, original);
    const Diagnostic d = tied_here ? atItsNote(a, original) : original;
    const bool elsewhere = other_file && !tied_here;
    json item = {{"range", rangeOf(a, elsewhere ? firstImport(a) : d.range)},
                 {"severity", d.severity == Severity::Error ? 1 : d.severity == Severity::Warning ? 2 : 3},
                 {"source", "sdfc"},
                 {"message", elsewhere ? "in '" + d.range.file->path + "': " + d.message : d.message}};
    if (!d.name.empty()) item["code"] = d.name;  // the warning's name, as in [-Wname]
    if (!d.notes.empty() || elsewhere) {
      json related = json::array();
      if (elsewhere) related.push_back({{"location", a.location(d.range)}, {"message", d.message}});
      for (const Diagnostic& n : d.notes) related.push_back({{"location", a.location(n.range)}, {"message", n.message}});
      item["relatedInformation"] = related;
    }
    list.push_back(std::move(item));
  }
  return {{"uri", a.uri}, {"version", a.version}, {"diagnostics", list}};
}

}  // namespace sdfc::lsp
