// Diagnostics as the editor shows them: the checker's own messages and
// ranges (the same as `sdfc check`), notes as related information.
#include <filesystem>

#include "check/point_file.h"
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

// Any other problem inside an imported file is shown on the import that
// names that file (else, reached through other files, on the first import),
// with its file and line in front, and its own place as related information.
SourceRange importOf(const Analysis& a, const SourceFile& file) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path target = fs::weakly_canonical(file.path, ec);
  SourceRange first;
  for (const ast::Statement& s : a.tree.statements) {
    if (!s.is_import) continue;
    if (!first.file) first = s.import_path_range;
    if (fs::weakly_canonical(resolveBesides(a.source().path, s.import_path), ec) == target) return s.import_path_range;
  }
  return first;
}

// "parts.sdf:3:5": the file as the document's folder names it (the absolute
// path repeated the editor's own knowledge), its line and column.
std::string placeIn(const Analysis& a, const SourceRange& r) {
  namespace fs = std::filesystem;
  const fs::path folder = fs::path(a.source().path).parent_path();
  std::string name = fs::path(r.file->path).lexically_relative(folder).string();
  if (name.empty() || name.rfind("..", 0) == 0) name = r.file->path;
  auto [line, col] = r.file->lineColumn(r.begin);
  return name + ":" + std::to_string(line) + ":" + std::to_string(col);
}

}  // namespace

json publishDiagnostics(const Analysis& a) {
  json list = json::array();
  for (const Diagnostic& original : a.diagnostics.all()) {
    const bool other_file = original.range.file && original.range.file != &a.source();
    const bool tied_here = other_file && hasNoteHere(a, original);
    const Diagnostic d = tied_here ? atItsNote(a, original) : original;
    const bool elsewhere = other_file && !tied_here;
    json item = {{"range", rangeOf(a, elsewhere ? importOf(a, *d.range.file) : d.range)},
                 {"severity", d.severity == Severity::Error ? 1 : d.severity == Severity::Warning ? 2 : 3},
                 {"source", "sdfc"},
                 {"message", elsewhere ? placeIn(a, d.range) + ": " + d.message : d.message}};
    if (!d.name.empty()) item["code"] = d.name;  // the warning's name, as in [-Wname]
    if (!d.notes.empty() || elsewhere) {
      json related = json::array();
      if (elsewhere) related.push_back({{"location", a.location(d.range)}, {"message", "here"}});
      for (const Diagnostic& n : d.notes) related.push_back({{"location", a.location(n.range)}, {"message", n.message}});
      item["relatedInformation"] = related;
    }
    list.push_back(std::move(item));
  }
  return {{"uri", a.uri}, {"version", a.version}, {"diagnostics", list}};
}

}  // namespace sdfc::lsp
