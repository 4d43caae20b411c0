#include "lsp/analysis.h"

#include <algorithm>
#include <set>

#include "syntax/lexer.h"
#include "syntax/parser.h"
#include "lsp/uri.h"

namespace sdfc::lsp {
namespace {

void indexExpr(Analysis& a, const ast::Expr& e) {
  if ((e.kind == ast::ExprKind::Name || e.kind == ast::ExprKind::Call) && a.lets.count(e.name))
    a.uses.push_back({e.name, e.kind == ast::ExprKind::Call ? e.name_range : e.range, false});
  for (const ast::ExprPtr& o : e.operands) indexExpr(a, *o);
  for (const ast::Argument& arg : e.arguments)
    if (arg.value) indexExpr(a, *arg.value);
  for (const ast::ExprPtr& c : e.children) indexExpr(a, *c);
}

void indexNodes(Analysis& a, const ir::Node& n, std::set<const ir::Node*>& seen) {
  if (!seen.insert(&n).second) return;
  if (n.range.file) a.nodes.emplace(n.range.begin, &n);
  for (const ir::NodeRef& c : n.children) indexNodes(a, *c, seen);
}

}  // namespace

std::shared_ptr<const Analysis> analyzeDocument(const Document& doc, bool utf8) {
  auto a = std::make_shared<Analysis>();
  a->uri = doc.uri;
  a->version = doc.version;
  CompileOptions options;
  options.fuse_transforms = false;  // keep one IR node per call, for hover
  options.produce_spirv = false;
  // The file's own path, so file("points.csv") is read beside it; a URI that
  // names no local file (untitled:) stands as the name, read relative to here.
  const std::string path = pathFromUri(doc.uri).value_or(doc.uri);
  a->compiled = checkSource(path, doc.text, options, a->diagnostics);
  Diagnostics again;  // the same syntax errors a second time: not reported twice
  a->tree = parse(*a->compiled.source, again, &a->comments);
  a->tokens = lex(*a->compiled.source, again);
  a->lines = LineIndex(a->compiled.source->text, utf8);
  for (const ast::Statement& s : a->tree.statements)
    if (s.is_let && !a->lets.count(s.name)) a->lets[s.name] = &s;
  for (const ast::Statement& s : a->tree.statements) {
    if (s.is_let) a->uses.push_back({s.name, s.name_range, true});
    if (s.value) indexExpr(*a, *s.value);
  }
  std::sort(a->uses.begin(), a->uses.end(),
            [](const NameUse& x, const NameUse& y) { return x.range.begin < y.range.begin; });
  std::set<const ir::Node*> seen;
  if (a->compiled.scene.root) indexNodes(*a, *a->compiled.scene.root, seen);
  return a;
}

const NameUse* Analysis::nameAt(size_t offset) const {
  for (const NameUse& u : uses)
    if (u.range.begin <= offset && offset <= u.range.end) return &u;
  return nullptr;
}

const ir::Node* Analysis::definitionNode(const std::string& name) const {
  for (const auto& [begin, node] : nodes)
    if (node->definition == name) return node;
  return nullptr;
}

}  // namespace sdfc::lsp
