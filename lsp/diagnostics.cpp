// Diagnostics as the editor shows them: the checker's own messages and
// ranges (the same as `sdfc check`), notes as related information.
#include "lsp/features.h"

namespace sdfc::lsp {
namespace {

json rangeOf(const Analysis& a, const SourceRange& r) {
  if (!r.file) return a.lines.rangeOf(0, 0);  // whole-file problems point at the start
  return a.lines.rangeOf(r.begin, std::max(r.begin, r.end));
}

}  // namespace

json publishDiagnostics(const Analysis& a) {
  json list = json::array();
  for (const Diagnostic& d : a.diagnostics.all()) {
    json item = {{"range", rangeOf(a, d.range)},
                 {"severity", d.severity == Severity::Error ? 1 : d.severity == Severity::Warning ? 2 : 3},
                 {"source", "sdfc"},
                 {"message", d.message}};
    if (!d.name.empty()) item["code"] = d.name;  // the warning's name, as in [-Wname]
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
