#include "syntax/lexer.h"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <string>

namespace sdfc {

const char* tokenKindName(TokenKind kind) {
  switch (kind) {
    case TokenKind::Identifier: return "identifier";
    case TokenKind::Number: return "number";
    case TokenKind::String: return "string";
    case TokenKind::KeywordLet: return "'let'";
    case TokenKind::LeftParen: return "'('";
    case TokenKind::RightParen: return "')'";
    case TokenKind::LeftBrace: return "'{'";
    case TokenKind::RightBrace: return "'}'";
    case TokenKind::LeftBracket: return "'['";
    case TokenKind::RightBracket: return "']'";
    case TokenKind::Comma: return "','";
    case TokenKind::Colon: return "':'";
    case TokenKind::Semicolon: return "';'";
    case TokenKind::Equals: return "'='";
    case TokenKind::Dot: return "'.'";
    case TokenKind::Plus: return "'+'";
    case TokenKind::Minus: return "'-'";
    case TokenKind::Star: return "'*'";
    case TokenKind::Slash: return "'/'";
    case TokenKind::EndOfFile: return "end of file";
    case TokenKind::Invalid: return "invalid token";
  }
  return "token";
}

namespace {

bool isIdentStart(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
bool isIdentChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }
bool isDigit(char c) { return c >= '0' && c <= '9'; }

TokenKind punctuation(char c) {
  switch (c) {
    case '(': return TokenKind::LeftParen;
    case ')': return TokenKind::RightParen;
    case '{': return TokenKind::LeftBrace;
    case '}': return TokenKind::RightBrace;
    case '[': return TokenKind::LeftBracket;
    case ']': return TokenKind::RightBracket;
    case ',': return TokenKind::Comma;
    case ':': return TokenKind::Colon;
    case ';': return TokenKind::Semicolon;
    case '=': return TokenKind::Equals;
    case '.': return TokenKind::Dot;
    case '+': return TokenKind::Plus;
    case '-': return TokenKind::Minus;
    case '*': return TokenKind::Star;
    case '/': return TokenKind::Slash;
    default: return TokenKind::Invalid;
  }
}

}  // namespace

std::vector<Token> lex(const SourceFile& file, Diagnostics& diags, std::vector<Comment>* comments) {
  std::vector<Token> tokens;
  const std::string& s = file.text;
  size_t i = 0;
  auto make = [&](TokenKind kind, size_t begin, size_t end) {
    Token t;
    t.kind = kind;
    t.range = {&file, begin, end};
    t.text = std::string_view(s).substr(begin, end - begin);
    return t;
  };
  while (i < s.size()) {
    const char c = s[i];
    if (c == ' ' || c == '\t' || c == '\r' || c == '\n') {
      ++i;
      continue;
    }
    // Comments: `//` to end of line and `/* ... */`.
    if (c == '/' && i + 1 < s.size() && s[i + 1] == '/') {
      const size_t begin = i;
      while (i < s.size() && s[i] != '\n') ++i;
      size_t end = i;
      while (end > begin + 2 && (s[end - 1] == '\r' || s[end - 1] == ' ' || s[end - 1] == '\t')) --end;
      if (comments) comments->push_back({{&file, begin, end}, true});
      continue;
    }
    if (c == '/' && i + 1 < s.size() && s[i + 1] == '*') {
      const size_t begin = i;
      const size_t close = s.find("*/", i + 2);
      if (close == std::string::npos) {
        diags.error({&file, begin, begin + 2}, "unterminated comment");
        i = s.size();
      } else {
        i = close + 2;
        if (comments) comments->push_back({{&file, begin, i}, false});
      }
      continue;
    }
    const size_t begin = i;
    if (isIdentStart(c)) {
      while (i < s.size() && isIdentChar(s[i])) ++i;
      Token t = make(TokenKind::Identifier, begin, i);
      if (t.text == "let") t.kind = TokenKind::KeywordLet;
      tokens.push_back(t);
      continue;
    }
    if (isDigit(c) || (c == '.' && i + 1 < s.size() && isDigit(s[i + 1]))) {
      while (i < s.size() && isDigit(s[i])) ++i;
      if (i < s.size() && s[i] == '.') {
        ++i;
        while (i < s.size() && isDigit(s[i])) ++i;
      }
      if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
        size_t j = i + 1;
        if (j < s.size() && (s[j] == '+' || s[j] == '-')) ++j;
        if (j < s.size() && isDigit(s[j])) {
          i = j;
          while (i < s.size() && isDigit(s[i])) ++i;
        }
      }
      // A letter glued to a number ("2x", "1e") is a typo, not two tokens.
      if (i < s.size() && isIdentChar(s[i])) {
        while (i < s.size() && isIdentChar(s[i])) ++i;
        diags.error({&file, begin, i}, "malformed number '" + s.substr(begin, i - begin) + "'");
        tokens.push_back(make(TokenKind::Invalid, begin, i));
        continue;
      }
      Token t = make(TokenKind::Number, begin, i);
      t.number = std::strtod(std::string(t.text).c_str(), nullptr);
      if (!std::isfinite(t.number)) {
        diags.error(t.range, "number '" + std::string(t.text) + "' is too large to be finite");
        t.kind = TokenKind::Invalid;
      }
      tokens.push_back(t);
      continue;
    }
    // A string: a file name, on one line, without escapes.
    if (c == '"') {
      ++i;
      while (i < s.size() && s[i] != '"' && s[i] != '\n') ++i;
      if (i >= s.size() || s[i] != '"') {
        diags.error({&file, begin, i}, "unterminated string (a string ends with '\"' on the same line)");
        tokens.push_back(make(TokenKind::Invalid, begin, i));
        continue;
      }
      ++i;
      tokens.push_back(make(TokenKind::String, begin, i));
      continue;
    }
    const TokenKind kind = punctuation(c);
    ++i;
    if (kind == TokenKind::Invalid) {
      // Group a run of bad bytes into one message (random input stays readable).
      while (i < s.size() && punctuation(s[i]) == TokenKind::Invalid && !isIdentStart(s[i]) &&
             !isDigit(s[i]) && !std::isspace(static_cast<unsigned char>(s[i])))
        ++i;
      const unsigned char shown = static_cast<unsigned char>(c);
      std::string what = std::isprint(shown) ? std::string("'") + c + "'" : "byte 0x" + [&] {
        char buf[4];
        std::snprintf(buf, sizeof buf, "%02x", shown);
        return std::string(buf);
      }();
      diags.error({&file, begin, i}, "unexpected character " + what);
      tokens.push_back(make(TokenKind::Invalid, begin, i));
      continue;
    }
    tokens.push_back(make(kind, begin, i));
  }
  tokens.push_back(make(TokenKind::EndOfFile, s.size(), s.size()));
  return tokens;
}

}  // namespace sdfc
