#include "syntax/lexer.h"

#include <cctype>
#include <cstdint>
#include <cstdio>
#include <utility>
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
    case TokenKind::KeywordImport: return "'import'";
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
bool isDecimalDigit(char c) { return c >= '0' && c <= '9'; }
bool isNonAscii(char c) { return static_cast<unsigned char>(c) >= 0x80; }

// The UTF-8 sequence at s[i]: its code point and length, or length 0 when
// the bytes are not valid UTF-8.
std::pair<uint32_t, size_t> decodeUtf8(const std::string& s, size_t i) {
  const unsigned char c = static_cast<unsigned char>(s[i]);
  size_t length = c >= 0xF0 && c < 0xF5 ? 4 : c >= 0xE0 ? 3 : c >= 0xC2 && c < 0xE0 ? 2 : 0;
  if (c >= 0xF5) length = 0;
  if (length == 0 || i + length > s.size()) return {0, 0};
  uint32_t cp = c & (0x7F >> length);
  for (size_t k = 1; k < length; ++k) {
    const unsigned char b = static_cast<unsigned char>(s[i + k]);
    if ((b & 0xC0) != 0x80) return {0, 0};
    cp = (cp << 6) | (b & 0x3F);
  }
  const uint32_t smallest[] = {0, 0, 0x80, 0x800, 0x10000};
  if (cp < smallest[length] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return {0, 0};
  return {cp, length};
}

// "U+00E8 'è'" for a valid character, "byte 0xc3" for a stray byte.
std::string describeNonAscii(const std::string& s, size_t i) {
  char buf[16];
  auto [cp, length] = decodeUtf8(s, i);
  if (length == 0) {
    std::snprintf(buf, sizeof buf, "byte 0x%02x", static_cast<unsigned char>(s[i]));
    return buf;
  }
  std::snprintf(buf, sizeof buf, "U+%04X", cp);
  return std::string(buf) + " '" + s.substr(i, length) + "'";
}

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
      while (i < s.size() && s[i] != '\n' && s[i] != '\r') ++i;
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
    if (isIdentStart(c) || isNonAscii(c)) {
      // Non-ASCII bytes glued to a name are taken into it, so "sphère" is
      // one token and one error, not three.
      size_t first_non_ascii = std::string::npos;
      while (i < s.size() && (isIdentChar(s[i]) || isNonAscii(s[i]))) {
        if (isNonAscii(s[i]) && first_non_ascii == std::string::npos) first_non_ascii = i;
        ++i;
      }
      Token t = make(TokenKind::Identifier, begin, i);
      if (first_non_ascii != std::string::npos) {
        bool has_ascii_letter = false;
        for (size_t k = begin; k < i; ++k) has_ascii_letter = has_ascii_letter || isIdentStart(s[k]);
        const std::string what = describeNonAscii(s, first_non_ascii);
        if (!has_ascii_letter) {
          // Only non-ASCII: a stray character (or binary junk), not a name.
          diags.error(t.range, "unexpected character " + what +
                                   (what[0] == 'U' ? "; outside comments, scene files are ASCII" : ""));
          t.kind = TokenKind::Invalid;
        } else {
          diags.error(t.range, "names use only ASCII letters, digits and '_'; '" + std::string(t.text) +
                                   "' contains " + what);
          t.bad_name = true;
        }
      }
      if (t.text == "let") t.kind = TokenKind::KeywordLet;
      if (t.text == "import") t.kind = TokenKind::KeywordImport;
      tokens.push_back(t);
      continue;
    }
    if (isDecimalDigit(c) || (c == '.' && i + 1 < s.size() && isDecimalDigit(s[i + 1]))) {
      while (i < s.size() && isDecimalDigit(s[i])) ++i;
      if (i < s.size() && s[i] == '.') {
        ++i;
        while (i < s.size() && isDecimalDigit(s[i])) ++i;
      }
      if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
        size_t j = i + 1;
        if (j < s.size() && (s[j] == '+' || s[j] == '-')) ++j;
        if (j < s.size() && isDecimalDigit(s[j])) {
          i = j;
          while (i < s.size() && isDecimalDigit(s[i])) ++i;
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
             !isNonAscii(s[i]) && !isDecimalDigit(s[i]) && !std::isspace(static_cast<unsigned char>(s[i])))
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
