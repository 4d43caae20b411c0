#include "lsp/analysis.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <set>

#include "api/scene.h"
#include "check/imports.h"
#include "check/parametric.h"
#include "syntax/lexer.h"
#include "syntax/parser.h"
#include "lsp/uri.h"

namespace sdfc::lsp {
namespace {

const ast::Parameter* parameterOf(const ast::Statement* s, const std::string& name) {
  if (!s) return nullptr;
  for (const ast::Parameter& p : s->params)
    if (p.name == name) return &p;
  return nullptr;
}

// `scope`: the parametric `let` being indexed (its parameters hide lets).
void indexExpr(Analysis& a, const ast::Expr& e, const ast::Statement* scope) {
  if (e.kind == ast::ExprKind::Name && parameterOf(scope, e.name))
    a.uses.push_back({e.name, e.range, false, scope});
  else if (e.kind == ast::ExprKind::Call && !a.lets.count(e.name) && a.importedAt(e.name))
    a.uses.push_back({e.name, e.name_range, false});
  else if (e.kind == ast::ExprKind::Member && e.operands[0]->kind == ast::ExprKind::Name &&
           a.importedAt(e.operands[0]->name + "." + e.name))
    a.uses.push_back({e.operands[0]->name + "." + e.name, e.range, false});
  else if (e.kind == ast::ExprKind::Name && !a.lets.count(e.name) && a.importedAt(e.name))
    a.uses.push_back({e.name, e.range, false});
  else if ((e.kind == ast::ExprKind::Name || e.kind == ast::ExprKind::Call) && a.lets.count(e.name))
    a.uses.push_back({e.name, e.kind == ast::ExprKind::Call ? e.name_range : e.range, false});
  // A named argument of a parametric definition's call is a use of its parameter.
  const ast::Statement* callee = nullptr;
  if (e.kind == ast::ExprKind::Call && a.lets.count(e.name) && a.lets.at(e.name)->has_params)
    callee = a.lets.at(e.name);
  for (const ast::ExprPtr& o : e.operands) indexExpr(a, *o, scope);
  for (const ast::Argument& arg : e.arguments) {
    if (!arg.name.empty() && parameterOf(callee, arg.name))
      a.uses.push_back({arg.name, arg.name_range, false, callee});
    if (arg.value) indexExpr(a, *arg.value, scope);
  }
  for (const ast::ExprPtr& c : e.children) indexExpr(a, *c, scope);
}

// `text`: the text of the file `s` is in (its ranges index it).
CalleeDoc definitionDoc(const std::string& text, const ast::Statement& s, const std::string& name,
                        const std::string& where) {
  CalleeDoc c{name, CalleeKind::Definition, where, {}, true};
  const std::vector<ParamUsage> uses = inferParameterUses(s);
  for (size_t i = 0; i < s.params.size(); ++i) {
    ParamDoc p;
    p.name = s.params[i].name;
    p.type = paramUseName(uses[i].use);
    if (s.params[i].default_value) {
      const SourceRange& r = s.params[i].default_value->range;
      p.fallback = r.begin <= r.end && r.end <= text.size() ? text.substr(r.begin, r.end - r.begin) : "";
    }
    p.required = !s.params[i].default_value;
    c.params.push_back(p);
  }
  return c;
}

void indexNodes(Analysis& a, const ir::Node& n, std::set<const ir::Node*>& seen) {
  if (!seen.insert(&n).second) return;
  if (n.range.file) a.nodes.emplace(n.range.begin, &n);
  for (const ir::NodeRef& c : n.children) indexNodes(a, *c, seen);
}

}  // namespace

std::string Analysis::importedKey(const std::string& name) const {
  if (imported.count(name)) return name;
  if (import_aliases.empty()) return "";
  return resolveImportedKey(import_aliases, name, 0, [&](const std::string& k) { return imported.count(k) > 0; });
}

const SourceRange* Analysis::importedAt(const std::string& name) const {
  auto it = imported.find(importedKey(name));
  return it != imported.end() ? &it->second : nullptr;
}

std::shared_ptr<const Analysis> analyzeDocument(const Document& doc, bool utf8) {
  auto a = std::make_shared<Analysis>();
  a->uri = doc.uri;
  a->version = doc.version;
  api::LoadOptions load;  // checked only, as `sdfc check` does
  load.compile.fuse_transforms = false;  // keep one IR node per call, for hover
  load.compile.produce_spirv = false;
  a->utf8 = utf8;
  // The file's own path, so file("points.csv") is read beside it; a URI that
  // names no local file (untitled:) stands as the name, read relative to here.
  const std::string path = pathFromUri(doc.uri).value_or(doc.uri);
  std::unique_ptr<api::Scene> scene = api::loadString(doc.text, path, load);
  a->compiled = std::move(scene->compiled);
  a->diagnostics = std::move(scene->diagnostics);
  Diagnostics again;  // the same syntax errors a second time: not reported twice
  a->tree = parse(*a->compiled.source, again, &a->comments);
  a->tokens = lex(*a->compiled.source, again);
  a->lines = LineIndex(a->compiled.source->text, utf8);
  // Imported definitions, by the names this file uses (files imported by
  // imported files are reached under their prefixes the same way).
  {
    Diagnostics quiet;  // the checker has reported them (a->tree, not a parse of its own: one tree less)
    const ImportSet imports = loadImports(a->tree, *a->compiled.source, quiet);
    a->import_aliases = imports.aliases;
    for (const ImportedDefinition& d : imports.definitions) {
      // The checker's files are the ones the ranges must point into.
      const std::string key = d.prefix + d.statement->name;
      for (const auto& f : a->compiled.scene.imported_sources)
        if (f->path == d.statement->name_range.file->path)
          a->imported.emplace(key, SourceRange{f.get(), d.statement->name_range.begin, d.statement->name_range.end});
      // For hover, from this read of the file (its ranges index this text).
      const std::string& text = d.statement->name_range.file->text;
      const SourceRange& r = d.statement->range;
      Analysis::ImportedDoc info;
      info.file = d.statement->name_range.file->path;
      if (r.begin <= r.end && r.end <= text.size()) info.text = text.substr(r.begin, r.end - r.begin);
      if (info.text.size() > 400) info.text = info.text.substr(0, 400) + " ...";
      info.parametric = d.statement->has_params;
      if (info.parametric)
        info.callee = definitionDoc(text, *d.statement, key, "defined in '" + info.file + "'");
      a->imported_docs.emplace(key, std::move(info));
    }
  }
  for (const ast::Statement& s : a->tree.statements)
    if (s.is_let && !a->lets.count(s.name)) a->lets[s.name] = &s;
  for (const ast::Statement& s : a->tree.statements) {
    if (s.is_let) a->uses.push_back({s.name, s.name_range, true});
    const ast::Statement* scope = s.is_let && s.has_params && a->lets[s.name] == &s ? &s : nullptr;
    for (const ast::Parameter& p : s.params) {
      if (scope) a->uses.push_back({p.name, p.name_range, true, scope});
      if (p.default_value) indexExpr(*a, *p.default_value, scope);
    }
    if (s.value) indexExpr(*a, *s.value, scope);
    if (scope) a->definitions.emplace(s.name, definitionDoc(a->text(), s, s.name, "defined in this file"));
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

// One decoder for every URI the server reads (lsp/uri.cpp); a URI that names
// no local file stands as it is.
std::string uriToPath(const std::string& uri) { return pathFromUri(uri).value_or(uri); }

std::string pathToUri(const std::string& path) {
  if (path.empty() || path[0] != '/') return path;
  static const char* kHex = "0123456789ABCDEF";
  std::string uri = "file://";
  for (unsigned char c : path) {
    if (std::isalnum(c) || std::strchr("/-._~", c)) {
      uri += static_cast<char>(c);
    } else {
      uri += '%';
      uri += kHex[c >> 4];
      uri += kHex[c & 15];
    }
  }
  return uri;
}

json Analysis::location(const SourceRange& r) const {
  if (!r.file || r.file == compiled.source.get())
    return {{"uri", uri}, {"range", lines.rangeOf(r.file ? r.begin : 0, r.file ? std::max(r.begin, r.end) : 0)}};
  const LineIndex other(r.file->text, utf8);
  std::string path = r.file->path;
  if (!path.empty() && path[0] != '/') path = std::filesystem::absolute(path).string();
  return {{"uri", pathToUri(path)}, {"range", other.rangeOf(r.begin, std::max(r.begin, r.end))}};
}

const CalleeDoc* Analysis::callee(const std::string& name) const {
  auto it = definitions.find(name);
  return it != definitions.end() ? &it->second : findCallee(name);
}

const ast::Statement* Analysis::enclosingDefinition(size_t offset) const {
  for (const ast::Statement& s : tree.statements)
    if (s.is_let && s.has_params && s.range.begin <= offset && offset <= s.range.end) return &s;
  return nullptr;
}

const ir::Node* Analysis::definitionNode(const std::string& name) const {
  for (const auto& [begin, node] : nodes)
    if (node->definition == name) return node;
  return nullptr;
}

}  // namespace sdfc::lsp
