// Document symbols: the settings, the `let` definitions and the scene tree.
#include "lsp/features.h"

namespace sdfc::lsp {
namespace {

constexpr int kSymbolNamespace = 3, kSymbolProperty = 7, kSymbolFunction = 12, kSymbolVariable = 13, kSymbolObject = 19;

json symbol(const Analysis& a, const std::string& name, int kind, const SourceRange& range,
            const SourceRange& selection, const std::string& detail = "") {
  json s = {{"name", name.empty() ? "?" : name}, {"kind", kind},
            {"range", a.lines.rangeOf(range.begin, std::max(range.end, selection.end))},
            {"selectionRange", a.lines.rangeOf(selection.begin, selection.end)}};
  if (!detail.empty()) s["detail"] = detail;
  return s;
}

json tree(const Analysis& a, const ast::Expr& e, int depth) {
  json children = json::array();
  if (depth < 64)
    for (const ast::ExprPtr& c : e.children) {
      if (c->kind == ast::ExprKind::Call) children.push_back(tree(a, *c, depth + 1));
      else if (c->kind == ast::ExprKind::Name)
        children.push_back(symbol(a, c->name, kSymbolVariable, c->range, c->range, "let shape"));
    }
  json s = symbol(a, e.name, e.name == "scene" ? kSymbolNamespace : kSymbolObject, e.range, e.name_range);
  if (!children.empty()) s["children"] = children;
  return s;
}

}  // namespace

json documentSymbols(const Analysis& a) {
  json out = json::array();
  for (const ast::Statement& s : a.tree.statements) {
    if (!s.value) continue;
    const ast::Expr& e = *s.value;
    if (s.is_let) {
      json sym = symbol(a, s.name, e.kind == ast::ExprKind::Call && !e.children.empty() ? kSymbolFunction : kSymbolVariable,
                        s.range, s.name_range);
      if (e.kind == ast::ExprKind::Call && e.has_block) sym["children"] = json::array({tree(a, e, 0)});
      out.push_back(sym);
    } else if (e.kind == ast::ExprKind::Call) {
      out.push_back(e.name == "scene" ? tree(a, e, 0) : symbol(a, e.name, kSymbolProperty, e.range, e.name_range));
    }
  }
  return out;
}

}  // namespace sdfc::lsp
