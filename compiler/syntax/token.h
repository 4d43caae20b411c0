// Tokens of the .sdf language (grammar/sdf.ebnf lists them).
#pragma once
#include <string_view>

#include "diag/source.h"

namespace sdfc {

enum class TokenKind {
  Identifier, Number, String, KeywordLet, KeywordImport,
  LeftParen, RightParen, LeftBrace, RightBrace, LeftBracket, RightBracket,
  Comma, Colon, Semicolon, Equals, Dot, Plus, Minus, Star, Slash,
  EndOfFile, Invalid,
};

struct Token {
  TokenKind kind = TokenKind::Invalid;
  SourceRange range;
  std::string_view text;
  double number = 0;  // for Number
  // Identifier: a name with non-ASCII letters ("sphère"). The lexer has
  // reported it; later stages treat it as unknown without saying more.
  bool bad_name = false;
};

// A comment the lexer skipped: kept for the formatter and the editor (trivia).
struct Comment {
  SourceRange range;  // from `//` or `/*` to the end of the line or `*/`
  bool line_comment = false;
};

const char* tokenKindName(TokenKind kind);

}  // namespace sdfc
