#include "format/same_tokens.h"

#include <algorithm>
#include <vector>

#include "syntax/lexer.h"
#include "syntax/parser.h"

namespace sdfc {
namespace {

// One token or comment, spelled as written (a string with its quotes, a number
// in its own spelling), in source order.
struct Item {
  std::string_view text;
  size_t offset;
  bool separator = false;  // ',' or ';'
  bool comment = false;
};

std::vector<Item> items(const SourceFile& file) {
  Diagnostics ignored;
  std::vector<Comment> comments;
  std::vector<Token> tokens = lex(file, ignored, &comments);
  tokens.pop_back();  // EndOfFile
  std::vector<Item> all;
  for (size_t i = 0; i < tokens.size(); ++i) {
    const TokenKind kind = tokens[i].kind;
    const TokenKind next = i + 1 < tokens.size() ? tokens[i + 1].kind : TokenKind::EndOfFile;
    if (kind == TokenKind::Semicolon) continue;
    if (kind == TokenKind::Comma && (next == TokenKind::RightParen || next == TokenKind::RightBracket)) continue;
    all.push_back({tokens[i].text, tokens[i].range.begin, kind == TokenKind::Comma || kind == TokenKind::Semicolon});
  }
  for (const Comment& c : comments)
    all.push_back({std::string_view(file.text).substr(c.range.begin, c.range.end - c.range.begin), c.range.begin,
                   false, true});
  std::stable_sort(all.begin(), all.end(), [](const Item& a, const Item& b) { return a.offset < b.offset; });
  // A comment may move across a ',' or ';' ("1 /* c */, 2" prints as
  // "1, /* c */"): separators go before the comments in front of them.
  std::vector<Item> out;
  for (const Item& item : all) {
    size_t at = out.size();
    if (item.separator)
      while (at > 0 && out[at - 1].comment) --at;
    out.insert(out.begin() + static_cast<std::ptrdiff_t>(at), item);
  }
  return out;
}

void shapeOf(const ast::Expr& e, std::string& out) {
  out += std::to_string(static_cast<int>(e.kind));
  if (e.op) out += e.op;
  out += e.name + (e.has_block ? "{" : "(");
  for (const ast::ExprPtr& o : e.operands) shapeOf(*o, out);
  for (const ast::Argument& a : e.arguments) {
    out += a.name + ":";
    shapeOf(*a.value, out);
  }
  out += "|";
  for (const ast::ExprPtr& c : e.children) shapeOf(*c, out);
  out += ")";
}

std::string shown(const SourceFile& file, const std::vector<Item>& list, size_t i) {
  if (i >= list.size()) return "the end of the file";
  std::string text(list[i].text.substr(0, 40));
  return "'" + text + (list[i].text.size() > 40 ? "...'" : "'") + " on line " +
         std::to_string(file.lineColumn(list[i].offset).first);
}

}  // namespace

std::string syntaxShape(const SourceFile& file) {
  Diagnostics diags;
  const ast::File tree = parse(file, diags);
  if (diags.hasErrors()) return "";
  std::string out;
  for (const ast::Statement& s : tree.statements) {
    // An import has no value: its path and alias are its whole shape.
    if (s.is_import) {
      out += "import " + s.import_path + " as " + s.alias + "\n";
      continue;
    }
    if (s.is_let) {
      out += "let " + s.name;
      if (s.has_params) {
        out += "(";
        for (const ast::Parameter& p : s.params) {
          out += p.name + ":";
          if (p.default_value) shapeOf(*p.default_value, out);
          out += ",";
        }
        out += ")";
      }
      out += "=";
    }
    if (s.value) shapeOf(*s.value, out);
    out += "\n";
  }
  return out;
}

std::string tokenDifference(const SourceFile& before, const SourceFile& after) {
  const std::vector<Item> a = items(before), b = items(after);
  size_t i = 0;
  while (i < a.size() && i < b.size() && a[i].text == b[i].text) ++i;
  if (i < a.size() || i < b.size()) return shown(before, a, i) + " became " + shown(after, b, i);
  if (syntaxShape(before) != syntaxShape(after)) return "the same tokens, grouped differently";
  return "";
}

}  // namespace sdfc
