#include "syntax/parser.h"

#include <algorithm>
#include <optional>

#include "syntax/lexer.h"

namespace sdfc {
namespace {

class Parser {
 public:
  Parser(const SourceFile& file, Diagnostics& diags, std::vector<Comment>* comments)
      : tokens_(lex(file, diags, comments)), diags_(diags) {}

  // file : { statement } EOF
  ast::File parseFile() {
    ast::File file;
    while (!at(TokenKind::EndOfFile)) {
      const size_t before = pos_;
      const int errors_before = diags_.errorCount();
      if (auto stmt = parseStatement()) file.statements.push_back(std::move(*stmt));
      if (pos_ == before) advance();  // always make progress
      // After an error, tokens that cannot start a statement are skipped
      // quietly: 100,000 stray '}' are one mistake, not 100,000.
      if (diags_.errorCount() > errors_before)
        while (!at(TokenKind::EndOfFile) && !at(TokenKind::Identifier) && !at(TokenKind::KeywordLet))
          advance();
    }
    return file;
  }

 private:
  std::vector<Token> tokens_;
  Diagnostics& diags_;
  size_t pos_ = 0;
  int depth_ = 0;
  // Set once a limit is hit: the rest of the file is skipped, and nothing
  // more is reported (no "expected ']'" for every level left open).
  bool abandoned_ = false;

  void abandon(SourceRange where, const std::string& message) {
    if (!abandoned_) diags_.error(where, message);
    abandoned_ = true;
    while (!at(TokenKind::EndOfFile)) advance();
  }
  void abandonTooDeep() {
    abandon(peek().range, "nesting is deeper than " + std::to_string(kMaxNestingDepth) + " levels");
  }
  // Heights are computed as nodes are built, so no tree taller than the
  // limit is ever made (or destroyed recursively).
  static int heightOf(const ast::Expr& e) {
    int h = 0;
    for (const ast::ExprPtr& o : e.operands) h = std::max(h, o->height);
    for (const ast::Argument& a : e.arguments) h = std::max(h, a.value->height);
    for (const ast::ExprPtr& c : e.children) h = std::max(h, c->height);
    return h + 1;
  }
  bool tooTall(int height, SourceRange where) {
    if (height <= kMaxExpressionHeight) return false;
    abandon(where, "this expression is more than " + std::to_string(kMaxExpressionHeight) +
                    " levels deep (each operator in a chain such as 'a + b + c' is a level); split "
                    "it with 'let'");
    return true;
  }

  const Token& peek(size_t ahead = 0) const {
    return tokens_[std::min(pos_ + ahead, tokens_.size() - 1)];
  }
  bool at(TokenKind kind) const { return peek().kind == kind; }
  const Token& advance() {
    const Token& t = peek();
    if (pos_ < tokens_.size() - 1) ++pos_;
    return t;
  }
  bool accept(TokenKind kind) {
    if (!at(kind)) return false;
    advance();
    return true;
  }
  // Reports "expected X" once at the current token; Invalid tokens were
  // already reported by the lexer, so they are not reported again.
  bool expect(TokenKind kind, const char* context) {
    if (accept(kind)) return true;
    if (!at(TokenKind::Invalid) && !abandoned_)
      diags_.error(peek().range, std::string("expected ") + tokenKindName(kind) + " " + context +
                                     ", found " + describe(peek()));
    return false;
  }
  static std::string describe(const Token& t) {
    if (t.kind == TokenKind::EndOfFile) return "end of file";
    return "'" + std::string(t.text) + "'";
  }

  // Skip to a token that can start a statement, for recovery.
  void synchronizeStatement() {
    int braces = 0;
    while (!at(TokenKind::EndOfFile)) {
      if (at(TokenKind::LeftBrace)) ++braces;
      if (at(TokenKind::RightBrace)) {
        if (braces == 0) {
          advance();
          return;
        }
        --braces;
      }
      if (braces == 0 && (at(TokenKind::Semicolon))) {
        advance();
        return;
      }
      if (braces == 0 && (at(TokenKind::KeywordLet) || at(TokenKind::KeywordImport))) return;
      advance();
    }
  }

  // statement : "let" IDENT [ parameters ] "=" expr [";"] | "import" STRING [ "as" IDENT ] [";"] | expr [";"]
  std::optional<ast::Statement> parseStatement() {
    ast::Statement stmt;
    const Token& first = peek();
    const size_t errors_before = diags_.errorCount();
    if (at(TokenKind::KeywordImport)) return parseImport();
    if (accept(TokenKind::KeywordLet)) {
      stmt.is_let = true;
      if (!at(TokenKind::Identifier)) {
        expect(TokenKind::Identifier, "after 'let'");
        synchronizeStatement();
        return std::nullopt;
      }
      const Token& name = advance();
      stmt.name = std::string(name.text);
      stmt.name_range = name.range;
      if (at(TokenKind::LeftParen) && !parseParameters(stmt)) {
        synchronizeStatement();
        return std::nullopt;
      }
      if (!expect(TokenKind::Equals, "after the name being defined")) {
        synchronizeStatement();
        return std::nullopt;
      }
    }
    stmt.value = parseExpr();
    stmt.range = first.range.to(tokens_[pos_ > 0 ? pos_ - 1 : 0].range);
    accept(TokenKind::Semicolon);
    if (diags_.errorCount() > errors_before && !at(TokenKind::EndOfFile) &&
        stmt.value->kind == ast::ExprKind::Error)
      synchronizeStatement();
    return stmt;
  }

  // parameters : "(" [ parameter { "," parameter } [","] ] ")"
  // parameter : IDENT [ ":" expr ]
  bool parseParameters(ast::Statement& stmt) {
    const Token& open = advance();  // '('
    stmt.has_params = true;
    stmt.params_range = open.range;
    while (!at(TokenKind::RightParen)) {
      if (!at(TokenKind::Identifier)) {
        expect(TokenKind::Identifier, "(a parameter's name)");
        return false;
      }
      ast::Parameter param;
      const Token& name = advance();
      param.name = std::string(name.text);
      param.name_range = name.range;
      if (accept(TokenKind::Colon)) {
        param.default_value = parseExpr();
        if (param.default_value->kind == ast::ExprKind::Error) return false;
      }
      stmt.params.push_back(std::move(param));
      if (!accept(TokenKind::Comma)) break;
    }
    stmt.params_range = stmt.params_range.to(peek().range);
    return expect(TokenKind::RightParen, "after the parameters");
  }

  // The import statement: `as` is an IDENT spelled "as", not a keyword.
  std::optional<ast::Statement> parseImport() {
    ast::Statement stmt;
    const Token& first = advance();  // 'import'
    stmt.is_import = true;
    if (!at(TokenKind::String)) {
      expect(TokenKind::String, "after 'import' (the path of a .sdf file)");
      synchronizeStatement();
      return std::nullopt;
    }
    const Token& path = advance();
    stmt.import_path = std::string(path.text.substr(1, path.text.size() - 2));
    stmt.import_path_range = path.range;
    if (at(TokenKind::Identifier) && peek().text == "as") {
      advance();
      if (!at(TokenKind::Identifier)) {
        expect(TokenKind::Identifier, "after 'as'");
        synchronizeStatement();
        return std::nullopt;
      }
      const Token& alias = advance();
      stmt.alias = std::string(alias.text);
      stmt.alias_range = alias.range;
    }
    stmt.range = first.range.to(tokens_[pos_ > 0 ? pos_ - 1 : 0].range);
    accept(TokenKind::Semicolon);
    return stmt;
  }

  ast::ExprPtr errorExpr(SourceRange range) {
    auto e = std::make_unique<ast::Expr>();
    e->kind = ast::ExprKind::Error;
    e->range = range;
    return e;
  }

  // expr : additive
  ast::ExprPtr parseExpr() {
    if (abandoned_) return errorExpr(peek().range);
    if (++depth_ > kMaxNestingDepth) {
      --depth_;
      abandonTooDeep();
      return errorExpr(peek().range);
    }
    auto e = parseAdditive();
    --depth_;
    return e;
  }

  ast::ExprPtr binary(char op, ast::ExprPtr lhs, ast::ExprPtr rhs) {
    auto e = std::make_unique<ast::Expr>();
    e->kind = ast::ExprKind::Binary;
    e->op = op;
    e->range = lhs->range.to(rhs->range);
    e->operands.push_back(std::move(lhs));
    e->operands.push_back(std::move(rhs));
    e->height = heightOf(*e);
    return e;
  }

  // additive : term { ("+" | "-") term }
  // A chain of operators builds a left-leaning tree one level per operator;
  // it stops (with one error) before growing past kMaxExpressionHeight.
  ast::ExprPtr parseAdditive() {
    auto lhs = parseTerm();
    while (at(TokenKind::Plus) || at(TokenKind::Minus)) {
      if (tooTall(lhs->height + 1, peek().range)) return errorExpr(peek().range);
      const char op = advance().text[0];
      lhs = binary(op, std::move(lhs), parseTerm());
    }
    return lhs;
  }

  // term : unary { ("*" | "/") unary }
  ast::ExprPtr parseTerm() {
    auto lhs = parseUnary();
    while (at(TokenKind::Star) || at(TokenKind::Slash)) {
      if (tooTall(lhs->height + 1, peek().range)) return errorExpr(peek().range);
      const char op = advance().text[0];
      lhs = binary(op, std::move(lhs), parseUnary());
    }
    return lhs;
  }

  // unary : "-" unary | postfix
  ast::ExprPtr parseUnary() {
    if (at(TokenKind::Minus)) {
      const Token& minus = advance();
      if (++depth_ > kMaxNestingDepth) {
        --depth_;
        abandonTooDeep();
        return errorExpr(peek().range);
      }
      auto operand = parseUnary();
      --depth_;
      auto e = std::make_unique<ast::Expr>();
      e->kind = ast::ExprKind::Unary;
      e->op = '-';
      e->range = minus.range.to(operand->range);
      e->operands.push_back(std::move(operand));
      e->height = heightOf(*e);
      if (tooTall(e->height, e->range)) return errorExpr(e->range);
      return e;
    }
    return parsePostfix();
  }

  // postfix : primary { "." IDENT }
  ast::ExprPtr parsePostfix() {
    auto e = parsePrimary();
    while (at(TokenKind::Dot)) {
      if (tooTall(e->height + 1, peek().range)) return errorExpr(peek().range);
      advance();
      if (!at(TokenKind::Identifier)) {
        expect(TokenKind::Identifier, "after '.'");
        return e;
      }
      const Token& field = advance();
      auto m = std::make_unique<ast::Expr>();
      m->kind = ast::ExprKind::Member;
      m->name = std::string(field.text);
      m->name_range = field.range;
      m->range = e->range.to(field.range);
      m->operands.push_back(std::move(e));
      m->height = heightOf(*m);
      e = std::move(m);
    }
    return e;
  }

  // primary : NUMBER | STRING | IDENT [ call_tail ] | IDENT "." IDENT call_tail | "[" expr { "," expr } [","] "]" | "(" expr ")"
  ast::ExprPtr parsePrimary() {
    const Token& t = peek();
    switch (t.kind) {
      case TokenKind::String: {
        advance();
        auto e = std::make_unique<ast::Expr>();
        e->kind = ast::ExprKind::String;
        e->name = std::string(t.text.substr(1, t.text.size() - 2));
        e->range = t.range;
        return e;
      }
      case TokenKind::Number: {
        advance();
        auto e = std::make_unique<ast::Expr>();
        e->kind = ast::ExprKind::Number;
        e->number = t.number;
        e->range = t.range;
        return e;
      }
      case TokenKind::Identifier: {
        advance();
        auto e = std::make_unique<ast::Expr>();
        e->name = std::string(t.text);
        e->name_range = t.range;
        e->range = t.range;
        e->bad_name = t.bad_name;
        // `parts.tower(...)`: a call of a definition imported `as parts`.
        if (at(TokenKind::Dot) && peek(1).kind == TokenKind::Identifier &&
            (peek(2).kind == TokenKind::LeftParen || peek(2).kind == TokenKind::LeftBrace)) {
          advance();
          const Token& member = advance();
          e->name += "." + std::string(member.text);
          e->name_range = t.range.to(member.range);
          e->range = e->name_range;
          e->bad_name = e->bad_name || member.bad_name;
        }
        if (at(TokenKind::LeftParen) || at(TokenKind::LeftBrace)) {
          e->kind = ast::ExprKind::Call;
          parseCallTail(*e);
          e->height = heightOf(*e);
          if (tooTall(e->height, e->range)) return errorExpr(e->range);
        } else {
          e->kind = ast::ExprKind::Name;
        }
        return e;
      }
      case TokenKind::LeftBracket: {
        advance();
        auto e = std::make_unique<ast::Expr>();
        e->kind = ast::ExprKind::Vector;
        if (!at(TokenKind::RightBracket)) {
          do {
            if (at(TokenKind::RightBracket)) break;  // trailing comma
            e->operands.push_back(parseExpr());
          } while (accept(TokenKind::Comma));
        }
        const Token& close = peek();
        if (!at(TokenKind::RightBracket) && !at(TokenKind::EndOfFile) && !abandoned_ &&
            !at(TokenKind::Invalid) && e->operands.back()->kind != ast::ExprKind::Error) {
          // "[1 1 1]": one error, and the vector is skipped whole, so neither
          // the call around it nor the checker reports it again.
          diags_.error(peek().range, "expected ',' or ']' in the vector, found " + describe(peek()));
          int depth = 0;
          while (!at(TokenKind::EndOfFile)) {
            if (at(TokenKind::LeftBracket)) ++depth;
            if (at(TokenKind::RightBracket) && depth-- == 0) break;
            if (depth == 0 && (at(TokenKind::RightParen) || at(TokenKind::RightBrace) ||
                               at(TokenKind::LeftBrace)))
              break;
            advance();
          }
          e->range = t.range.to(peek().range);
          accept(TokenKind::RightBracket);
          // Not an Error node: the statement around it parsed on, so nothing
          // after it is skipped.
          e->reported = true;
          return e;
        }
        expect(TokenKind::RightBracket, "to close the vector");
        e->range = t.range.to(close.range);
        if (e->operands.empty() && !abandoned_) diags_.error(e->range, "a vector needs at least one element");
        e->height = heightOf(*e);
        if (tooTall(e->height, e->range)) return errorExpr(e->range);
        return e;
      }
      case TokenKind::LeftParen: {
        advance();
        auto inner = parseExpr();
        const Token& close = peek();
        expect(TokenKind::RightParen, "to close '('");
        inner->paren_range = t.range.to(close.range);
        return inner;
      }
      case TokenKind::Invalid:
        advance();
        return errorExpr(t.range);
      default:
        if (!abandoned_) diags_.error(t.range, "expected an expression, found " + describe(t));
        return errorExpr(t.range);
    }
  }

  // call_tail : [ "(" [ argument { "," argument } [","] ] ")" ] [ block ]
  // argument  : [ IDENT ":" ] expr
  void parseCallTail(ast::Expr& call) {
    if (accept(TokenKind::LeftParen)) {
      bool reported = false;
      while (!at(TokenKind::RightParen) && !at(TokenKind::EndOfFile)) {
        ast::Argument arg;
        if (at(TokenKind::Identifier) && peek(1).kind == TokenKind::Colon) {
          const Token& name = advance();
          arg.name = std::string(name.text);
          arg.name_range = name.range;
          advance();  // ':'
        }
        arg.value = parseExpr();
        if (arg.name_range.file == nullptr) arg.name_range = arg.value->range;
        const bool was_error = arg.value->kind == ast::ExprKind::Error;
        call.arguments.push_back(std::move(arg));
        if (accept(TokenKind::Comma)) continue;
        if (!at(TokenKind::RightParen)) {
          if (!was_error) expect(TokenKind::RightParen, "after the arguments");
          reported = true;
          // Recover: skip to the closing parenthesis of this call.
          int parens = 0;
          while (!at(TokenKind::EndOfFile)) {
            if (at(TokenKind::LeftParen)) ++parens;
            if (at(TokenKind::RightParen) && parens-- == 0) break;
            if (at(TokenKind::LeftBrace) || at(TokenKind::RightBrace)) break;
            advance();
          }
          break;
        }
      }
      call.range = call.range.to(peek().range);
      // "a(" or "a(1," at the end of the file was taken as closed.
      if (!accept(TokenKind::RightParen) && !reported) expect(TokenKind::RightParen, "to close the arguments");
    }
    if (at(TokenKind::LeftBrace)) parseBlock(call);
  }

  // block : "{" { expr [";"] } "}"
  void parseBlock(ast::Expr& call) {
    const Token& open = advance();
    call.has_block = true;
    while (!at(TokenKind::RightBrace) && !at(TokenKind::EndOfFile)) {
      const size_t before = pos_;
      auto child = parseExpr();
      const bool bad = child->kind == ast::ExprKind::Error;
      call.children.push_back(std::move(child));
      accept(TokenKind::Semicolon);
      if (pos_ == before || bad) {
        // Skip to the next item or the end of this block.
        while (!at(TokenKind::EndOfFile) && !at(TokenKind::RightBrace) &&
               !at(TokenKind::Identifier))
          advance();
      }
    }
    const Token& close = peek();
    if (!accept(TokenKind::RightBrace) && !abandoned_) {
      Diagnostic& d = diags_.error(close.range, "expected '}' to close the block");
      d.notes.push_back({Severity::Note, open.range, "the block opens here", {}});
    }
    call.range = call.range.to(close.range);
  }
};

}  // namespace

ast::File parse(const SourceFile& file, Diagnostics& diags, std::vector<Comment>* comments) {
  Parser parser(file, diags, comments);
  return parser.parseFile();
}

}  // namespace sdfc
