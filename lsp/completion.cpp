// Completion (built-ins, parameter names with their defaults, names in scope)
// and signature help. Both read the tokens before the cursor rather than the
// tree, so they work in the half-typed text an editor sends.
#include <set>

#include "ir/expr.h"
#include "lsp/catalogue.h"
#include "lsp/features.h"

namespace sdfc::lsp {
namespace {

enum class Where { TopLevel, Block, Arguments, Vector };

struct Context {
  Where where = Where::TopLevel;
  std::string callee;             // Arguments: the call's name
  int commas = 0;                 // Arguments: commas before the cursor at this level
  std::string active_name;        // Arguments: the named argument being written
  std::set<std::string> given;    // Arguments: names already written
  const Token* previous = nullptr;  // the token before the cursor (or the word being typed)
};

// The tokens before `offset`, without the identifier being typed at it.
size_t contextEnd(const Analysis& a, size_t offset) {
  size_t n = 0;
  while (n < a.tokens.size() && a.tokens[n].kind != TokenKind::EndOfFile && a.tokens[n].range.end <= offset) ++n;
  if (n > 0 && a.tokens[n - 1].kind == TokenKind::Identifier && a.tokens[n - 1].range.end == offset) --n;
  // The cursor inside a word also types that word.
  return n;
}

Context contextAt(const Analysis& a, size_t offset, bool skip_vectors) {
  Context c;
  const size_t end = contextEnd(a, offset);
  if (end > 0) c.previous = &a.tokens[end - 1];
  int depth = 0;
  for (size_t i = end; i-- > 0;) {
    const Token& t = a.tokens[i];
    switch (t.kind) {
      case TokenKind::RightParen:
      case TokenKind::RightBracket:
      case TokenKind::RightBrace: ++depth; break;
      case TokenKind::Comma:
        if (depth == 0) ++c.commas;
        break;
      case TokenKind::Colon:
        if (depth == 0 && i > 0 && a.tokens[i - 1].kind == TokenKind::Identifier) {
          const std::string name(a.tokens[i - 1].text);
          c.given.insert(name);
          if (c.commas == 0 && c.active_name.empty()) c.active_name = name;
        }
        break;
      case TokenKind::LeftBracket:
        if (depth > 0) {
          --depth;
        } else if (!skip_vectors) {
          c.where = Where::Vector;
          return c;
        } else {
          // Inside a vector argument: the commas so far were the vector's.
          c.commas = 0;
          c.active_name.clear();
          c.given.clear();
        }
        break;
      case TokenKind::LeftParen:
      case TokenKind::LeftBrace:
        if (depth > 0) {
          --depth;
          break;
        }
        if (t.kind == TokenKind::LeftParen && i > 0 && a.tokens[i - 1].kind == TokenKind::Identifier) {
          c.where = Where::Arguments;
          c.callee = std::string(a.tokens[i - 1].text);
        } else {
          c.where = t.kind == TokenKind::LeftBrace ? Where::Block : Where::Vector;
        }
        return c;
      default: break;
    }
  }
  return c;
}

json item(const std::string& label, int kind, const std::string& detail, const std::string& sort,
          const std::string& doc = "", const std::string& insert = "") {
  json j = {{"label", label}, {"kind", kind}, {"detail", detail}, {"sortText", sort + label}};
  if (!doc.empty()) j["documentation"] = {{"kind", "markdown"}, {"value", doc}};
  if (!insert.empty()) j["insertText"] = insert;
  return j;
}

constexpr int kItemFunction = 3, kItemField = 5, kItemVariable = 6, kItemKeyword = 14, kItemConstant = 21, kItemModule = 9;

void addLets(const Analysis& a, json& out, size_t offset) {
  if (const ast::Statement* def = a.enclosingDefinition(offset))
    if (const CalleeDoc* c = a.callee(def->name))
      for (const ParamDoc& p : c->params) out.push_back(item(p.name, kItemVariable, p.label(), "0", "parameter of `" + def->name + "`"));
  for (const auto& [name, s] : a.lets) {
    if (s->has_params) {
      if (const CalleeDoc* c = a.callee(name)) out.push_back(item(name, kItemFunction, c->signature(), "1", c->markdown()));
      continue;
    }
    std::string value = a.text().substr(s->range.begin, s->range.end - s->range.begin);
    if (value.find('\n') != std::string::npos) value = value.substr(0, value.find('\n')) + " ...";
    out.push_back(item(name, kItemVariable, value, "1"));
  }
}

void addCallees(json& out, bool shapes, bool values, bool settings) {
  for (const CalleeDoc& c : callees()) {
    const bool shape = c.kind == CalleeKind::Primitive || c.kind == CalleeKind::Operator;
    const bool value = c.kind == CalleeKind::Math || c.kind == CalleeKind::Material ||
                       c.kind == CalleeKind::Field;
    const bool setting = c.kind == CalleeKind::Setting || c.kind == CalleeKind::Scene;
    if ((shape && shapes) || (value && values) || (setting && settings))
      out.push_back(item(c.name, c.kind == CalleeKind::Scene ? kItemModule : kItemFunction, c.signature(), "2",
                         c.markdown()));
  }
}

}  // namespace

json completion(const Analysis& a, size_t offset) {
  json out = json::array();
  const Context c = contextAt(a, offset, false);
  const bool at_name = c.previous && (c.previous->kind == TokenKind::LeftParen || c.previous->kind == TokenKind::Comma);
  switch (c.where) {
    case Where::Arguments:
      if (at_name)
        if (const CalleeDoc* callee = a.callee(c.callee))
          for (const ParamDoc& p : callee->params)
            if (!c.given.count(p.name))
              out.push_back(item(p.name, kItemField, p.label(), "0",
                                 p.required ? "required" : (p.fallback.empty() ? "optional" : "default " + p.fallback),
                                 p.name + ": "));
      [[fallthrough]];
    case Where::Vector:
      addLets(a, out, offset);
      out.push_back(item("time", kItemConstant, "scene time in seconds", "1"));
      out.push_back(item("pi", kItemConstant, "3.14159265358979", "1"));
      addCallees(out, true, true, false);
      break;
    case Where::Block:
      addLets(a, out, offset);
      addCallees(out, true, false, false);
      break;
    case Where::TopLevel:
      if (c.previous && c.previous->kind == TokenKind::Equals) {  // let name = |
        addLets(a, out, offset);
        addCallees(out, true, true, false);
        break;
      }
      out.push_back(item("let", kItemKeyword, "let name = value", "0"));
      addCallees(out, false, false, true);
      break;
  }
  return {{"isIncomplete", false}, {"items", out}};
}

json signatureHelp(const Analysis& a, size_t offset) {
  const Context c = contextAt(a, offset, true);
  if (c.where != Where::Arguments) return nullptr;
  const CalleeDoc* callee = a.callee(c.callee);
  if (!callee) return nullptr;
  json params = json::array();
  std::string label = callee->name + "(";
  int active = -1;
  for (size_t i = 0; i < callee->params.size(); ++i) {
    const ParamDoc& p = callee->params[i];
    if (i) label += ", ";
    const size_t begin = label.size();
    label += p.label();
    params.push_back({{"label", {begin, label.size()}},
                      {"documentation", p.required ? "required" : (p.fallback.empty() ? "optional" : "default " + p.fallback)}});
    if (p.name == c.active_name) active = static_cast<int>(i);
  }
  label += ")";
  if (active < 0 && c.active_name.empty() && c.given.empty()) active = c.commas;
  json sig = {{"label", label}, {"documentation", {{"kind", "markdown"}, {"value", callee->markdown()}}},
              {"parameters", params}};
  return {{"signatures", json::array({sig})}, {"activeSignature", 0},
          {"activeParameter", active < 0 ? static_cast<int>(callee->params.size()) : active}};
}

}  // namespace sdfc::lsp
