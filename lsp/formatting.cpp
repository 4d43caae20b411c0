// Format document: `sdfc fmt`'s layout as one edit; no edit when the
// document has syntax errors or is already formatted.
#include "format/formatter.h"
#include "lsp/features.h"

namespace sdfc::lsp {

json formatting(const Analysis& a) {
  Diagnostics ignored;
  const std::optional<std::string> formatted = formatSource(a.source(), ignored);
  if (!formatted || *formatted == a.text()) return json::array();
  return json::array({{{"range", a.lines.rangeOf(0, a.text().size())}, {"newText", *formatted}}});
}

}  // namespace sdfc::lsp
