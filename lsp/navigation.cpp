// Go to definition, find references, highlight and rename for `let` names
// (visible in the whole file) and the parameters of parametric ones
// (visible in their definition, and as argument names at its calls).

#include "check/builtins.h"
#include "lsp/features.h"

namespace sdfc::lsp {
namespace {

json location(const Analysis& a, const SourceRange& r) {
  return {{"uri", a.uri}, {"range", a.lines.rangeOf(r.begin, r.end)}};
}

}  // namespace

json definition(const Analysis& a, size_t offset) {
  const NameUse* use = a.nameAt(offset);
  if (!use) return nullptr;
  if (use->scope)
    for (const ast::Parameter& p : use->scope->params)
      if (p.name == use->name) return location(a, p.name_range);
  if (!a.lets.count(use->name)) {
    const SourceRange* at = a.importedAt(use->name);
    return at ? a.location(*at) : json(nullptr);
  }
  return location(a, a.lets.at(use->name)->name_range);
}

namespace {
bool same(const NameUse& u, const NameUse& v) { return u.name == v.name && u.scope == v.scope; }
}  // namespace

json references(const Analysis& a, size_t offset, bool include_declaration) {
  const NameUse* use = a.nameAt(offset);
  json out = json::array();
  if (!use) return out;
  for (const NameUse& u : a.uses)
    if (same(u, *use) && (include_declaration || !u.definition)) out.push_back(location(a, u.range));
  return out;
}

json documentHighlight(const Analysis& a, size_t offset) {
  const NameUse* use = a.nameAt(offset);
  json out = json::array();
  if (!use) return out;
  for (const NameUse& u : a.uses)
    if (same(u, *use))
      out.push_back({{"range", a.lines.rangeOf(u.range.begin, u.range.end)}, {"kind", u.definition ? 3 : 2}});
  return out;
}

json prepareRename(const Analysis& a, size_t offset) {
  const NameUse* use = a.nameAt(offset);
  if (!use) return nullptr;
  return {{"range", a.lines.rangeOf(use->range.begin, use->range.end)}, {"placeholder", use->name}};
}

json rename(const Analysis& a, size_t offset, const std::string& new_name) {
  const NameUse* use = a.nameAt(offset);
  if (!use) throw RpcError(kRequestFailed, "only a name bound by 'let' can be renamed");
  if (!use->scope && !a.lets.count(use->name))
    throw RpcError(kRequestFailed, "'" + use->name + "' is imported; rename it in the file that defines it");
  // [A-Za-z_][A-Za-z0-9_]*, checked by hand: std::regex recursed once per
  // character and a 30,000-character name overflowed the stack.
  auto letter = [](char c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '_'; };
  bool identifier = !new_name.empty() && letter(new_name[0]);
  for (char c : new_name) identifier = identifier && (letter(c) || (c >= '0' && c <= '9'));
  if (!identifier || new_name == "let")
    throw RpcError(kRequestFailed, "'" + new_name + "' is not a valid name");
  if (isReservedName(new_name))
    throw RpcError(kRequestFailed, "'" + new_name + "' is a built-in name");
  if (new_name != use->name && !use->scope && a.lets.count(new_name))
    throw RpcError(kRequestFailed, "'" + new_name + "' is already defined");
  if (use->scope && new_name != use->name)
    for (const ast::Parameter& p : use->scope->params)
      if (p.name == new_name) throw RpcError(kRequestFailed, "'" + new_name + "' is already a parameter");
  json edits = json::array();
  for (const NameUse& u : a.uses)
    if (same(u, *use))
      edits.push_back({{"range", a.lines.rangeOf(u.range.begin, u.range.end)}, {"newText", new_name}});
  return {{"changes", {{a.uri, edits}}}};
}

}  // namespace sdfc::lsp
