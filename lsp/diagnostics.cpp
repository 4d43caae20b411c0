// Diagnostics as the editor shows them: the checker's own messages and
// ranges (the same as `sdfc check`), notes as related information.
#include "lsp/features.h"

namespace sdfc::lsp {
namespace {

json rangeOf(const Analysis& a, const SourceRange& r) {
  if (!r.file) return a.lines.rangeOf(0, 0);  // whole-file problems point at the start
  return a.lines.rangeOf(r.begin, std::max(r.begin, r.end));
}

// A problem inside an imported file is shown on this file's first import,
// named after that file, with its own place as related information.
SourceRange firstImport(const Analysis& a) {
  for (const ast::Statement& s : a.tree.statements)
    if (s.is_import) return s.import_path_range;
  return {};
}

}  // namespace

json publishDiagnostics(const Analysis& a) {
  json list = json::array();
  for (const Diagnostic& d : a.diagnostics.all()) {
    const bool elsewhere = d.range.file && d.range.file != &a.source();
    json item = {{"range", rangeOf(a, elsewhere ? firstImport(a) : d.range)},
                 {"severity", d.severity == Severity::Error ? 1 : d.severity == Severity::Warning ? 2 : 3},
                 {"source", "sdfc"},
                 {"message", elsewhere ? "in '" + d.range.file->path + "': " + d.message : d.message}};
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
