#include "format/formatter.h"

#include <algorithm>

#include "format/same_tokens.h"
#include "syntax/parser.h"

// Layout rules (docs/editors.md lists them for users):
//  - one statement a line, two-space indentation, at most one blank line kept
//    where the source had one or more; none at the start or end of a block;
//  - `name: value` arguments joined by ", ", binary operators spaced, no
//    space inside (), [] or {} except one inside a one-line block;
//  - a block stays on one line when it was written on one line and holds no
//    comment; otherwise one child a line;
//  - an argument list or vector holding a comment is broken one item a line
//    with a trailing comma; parentheses are kept as written, every level;
//  - `;` only where the next item would otherwise continue this one (it
//    starts with '(' or '-'); numbers keep their spelling;
//  - comments keep their place: at the end of a line or on their own line.

namespace sdfc {
namespace {

class Printer {
 public:
  Printer(const SourceFile& file, std::vector<Comment> comments)
      : src_(file.text), comments_(std::move(comments)) {}

  std::string run(const ast::File& file) {
    for (size_t i = 0; i < file.statements.size(); ++i) {
      const ast::Statement& s = file.statements[i];
      beginItem(s.range.begin);
      if (s.is_import) {
        importStatement(s);
        continue;
      }
      if (s.is_let) {
        write("let", s.range.begin, s.range.begin + 3);
        raw(" ");
        write(s.name, s.name_range.begin, s.name_range.end);
        if (s.has_params) parameters(s);
        // '=' and ':' at their source places, so a comment before them stays there.
        const size_t equals = nextToken(s.has_params ? s.params_range.end : s.name_range.end);
        raw(" ");
        write("=", equals, equals + 1);
        raw(" ");
      }
      expr(*s.value);
      if (i + 1 < file.statements.size() && !file.statements[i + 1].is_let &&
          !file.statements[i + 1].is_import && needsSemicolon(*file.statements[i + 1].value))
        raw(";");
    }
    flushComments(src_.size(), true);
    trimTrailingSpaces();
    if (!out_.empty() && out_.back() != '\n') out_ += '\n';
    return alignTrailingComments();
  }

 private:
  const std::string& src_;
  std::vector<Comment> comments_;
  size_t next_comment_ = 0;
  std::string out_;
  int indent_ = 0;
  bool line_start_ = true;
  size_t last_src_end_ = 0;  // source offset just past the last token or comment written
  std::vector<size_t> trailing_;  // offsets in out_ of `//` comments that end a line of code

  // Line comments at the ends of consecutive lines start in one column, two
  // spaces past the longest code among them (as the hand-aligned examples had).
  std::string alignTrailingComments() const {
    std::vector<std::string> lines;
    std::vector<size_t> comment_col;  // npos: no trailing comment on that line
    size_t start = 0, t = 0;
    while (start < out_.size()) {
      const size_t end = out_.find('\n', start);
      lines.push_back(out_.substr(start, end - start));
      size_t col = std::string::npos;
      while (t < trailing_.size() && trailing_[t] < end) col = trailing_[t++] - start;
      comment_col.push_back(col);
      start = end + 1;
    }
    std::string result;
    for (size_t i = 0; i < lines.size();) {
      size_t j = i, width = 0;
      while (j < lines.size() && comment_col[j] != std::string::npos) width = std::max(width, comment_col[j++] - 1);
      if (j == i) {
        result += lines[i++] + '\n';
        continue;
      }
      for (; i < j; ++i) {
        const std::string code = lines[i].substr(0, comment_col[i] - 1);
        result += code + std::string(width + 2 - code.size(), ' ') + lines[i].substr(comment_col[i]) + '\n';
      }
    }
    return result;
  }

  // ---- source positions -----------------------------------------------------

  // The offset of the next token at or after `pos`, skipping spaces and comments.
  size_t nextToken(size_t pos) const {
    while (pos < src_.size()) {
      const char c = src_[pos];
      if (c == ' ' || c == '\t' || c == '\r' || c == '\n') {
        ++pos;
      } else if (src_.compare(pos, 2, "//") == 0) {
        while (pos < src_.size() && src_[pos] != '\n') ++pos;
      } else if (src_.compare(pos, 2, "/*") == 0) {
        const size_t close = src_.find("*/", pos + 2);
        pos = close == std::string::npos ? src_.size() : close + 2;
      } else {
        break;
      }
    }
    return pos;
  }
  static size_t fullBegin(const ast::Expr& e) {
    if (e.paren_range.file) return e.paren_range.begin;
    if ((e.kind == ast::ExprKind::Binary || e.kind == ast::ExprKind::Member) && !e.operands.empty())
      return fullBegin(*e.operands[0]);
    return e.range.begin;
  }
  static size_t fullEnd(const ast::Expr& e) {
    if (e.paren_range.file) return e.paren_range.end;
    if ((e.kind == ast::ExprKind::Binary || e.kind == ast::ExprKind::Unary) && !e.operands.empty())
      return fullEnd(*e.operands.back());
    return e.range.end;
  }
  bool newlineBetween(size_t a, size_t b) const {
    return src_.find('\n', a) < std::min(b, src_.size());
  }
  // A blank line in the source right before `pos` (only spaces behind it).
  bool blankBefore(size_t pos) const {
    int newlines = 0;
    while (pos > 0) {
      const char c = src_[pos - 1];
      if (c == '\n') ++newlines;
      else if (c != ' ' && c != '\t' && c != '\r') break;
      --pos;
    }
    return newlines >= 2 && pos > 0;
  }
  bool commentWithin(size_t begin, size_t end) const {
    for (size_t i = next_comment_; i < comments_.size(); ++i) {
      if (comments_[i].range.begin >= end) break;
      if (comments_[i].range.begin >= begin) return true;
    }
    return false;
  }

  // ---- output ---------------------------------------------------------------

  void trimTrailingSpaces() {
    while (!out_.empty() && out_.back() == ' ') out_.pop_back();
  }
  void newline() {
    trimTrailingSpaces();
    out_ += '\n';
    line_start_ = true;
  }
  void ensureNewline() {
    if (!line_start_) newline();
  }
  void raw(const std::string& text) {
    if (line_start_) {
      out_.append(2 * indent_, ' ');
      line_start_ = false;
    }
    out_ += text;
  }
  // A token from the source at [begin, end): comments before it come first.
  void write(const std::string& text, size_t begin, size_t end) {
    flushComments(begin, false);
    raw(text);
    last_src_end_ = end;
  }
  bool canAddBlank() const {
    if (out_.size() < 2 || out_.back() != '\n' || out_[out_.size() - 2] == '\n') return false;
    size_t i = out_.size() - 1;
    while (i > 0 && (out_[i - 1] == ' ')) --i;
    return out_[i - 1] != '{' && out_[i - 1] != '(' && out_[i - 1] != '[';
  }
  // Writes the comments that start before `pos`. A comment on the same source
  // line as the last token stays at the end of that line; others get their
  // own line. With `trailing_only`, stops at the first own-line comment.
  void flushComments(size_t pos, bool at_end, bool trailing_only = false) {
    while (next_comment_ < comments_.size() && comments_[next_comment_].range.begin < pos) {
      const Comment& c = comments_[next_comment_];
      const bool trailing = !line_start_ && !newlineBetween(last_src_end_, c.range.begin) &&
                            last_src_end_ > 0;
      if (trailing_only && !trailing) return;
      const std::string text = src_.substr(c.range.begin, c.range.end - c.range.begin);
      if (trailing) {
        trimTrailingSpaces();
        out_ += ' ';
        if (c.line_comment) trailing_.push_back(out_.size());
        out_ += text;
      } else {
        ensureNewline();
        if (blankBefore(c.range.begin) && canAddBlank()) out_ += '\n';
        raw(text);
      }
      last_src_end_ = c.range.end;
      ++next_comment_;
      // A line comment ends its line; a block comment does when the source
      // broke the line after it.
      size_t next = nextToken(c.range.end);
      if (next_comment_ < comments_.size()) next = std::min(next, comments_[next_comment_].range.begin);
      if (c.line_comment || at_end || newlineBetween(c.range.end, next))
        newline();
      else
        raw(" ");
    }
  }
  // Starts an item of a statement list or multi-line block at `pos`.
  void beginItem(size_t pos) {
    flushComments(pos, false, true);
    ensureNewline();
    flushComments(pos, false);
    ensureNewline();
    if (blankBefore(pos) && canAddBlank()) out_ += '\n';
  }

  // ---- the tree -------------------------------------------------------------

  // import "parts.sdf" [as parts]; the path keeps its spelling.
  void importStatement(const ast::Statement& s) {
    write("import", s.range.begin, s.range.begin + 6);
    raw(" ");
    const SourceRange& p = s.import_path_range;
    write(src_.substr(p.begin, p.end - p.begin), p.begin, p.end);
    if (!s.alias.empty()) {
      raw(" ");
      const size_t as = nextToken(p.end);
      write("as", as, as + 2);
      raw(" ");
      write(s.alias, s.alias_range.begin, s.alias_range.end);
    }
  }

  // (a, b: 1): laid out as an argument list.
  void parameters(const ast::Statement& s) {
    const SourceRange& r = s.params_range;
    write("(", r.begin, r.begin + 1);
    list(s.params.size(), r.begin, r.end - 1, [&](size_t i) { return s.params[i].name_range.begin; },
         [&](size_t i) {
           const ast::Parameter& p = s.params[i];
           write(p.name, p.name_range.begin, p.name_range.end);
           if (p.default_value) {
             const size_t colon = nextToken(p.name_range.end);
             write(":", colon, colon + 1);
             raw(" ");
             expr(*p.default_value);
           }
         });
    write(")", r.end - 1, r.end);
  }

  // True when `next` would glue onto the item before it without a ';'.
  static bool needsSemicolon(const ast::Expr& next) {
    if (next.paren_range.file) return true;
    switch (next.kind) {
      case ast::ExprKind::Unary: return true;
      case ast::ExprKind::Binary:
      case ast::ExprKind::Member: return needsSemicolon(*next.operands[0]);
      default: return false;
    }
  }

  // Where `e` begins and ends inside its own parentheses.
  static size_t bareBegin(const ast::Expr& e) {
    if ((e.kind == ast::ExprKind::Binary || e.kind == ast::ExprKind::Member) && !e.operands.empty())
      return fullBegin(*e.operands[0]);
    return e.range.begin;
  }
  static size_t bareEnd(const ast::Expr& e) {
    if ((e.kind == ast::ExprKind::Binary || e.kind == ast::ExprKind::Unary) && !e.operands.empty())
      return fullEnd(*e.operands.back());
    return e.range.end;
  }

  void expr(const ast::Expr& e) {
    if (!e.paren_range.file) {
      bare(e);
      return;
    }
    // Every level as written: "((a))" stays, formatting changes only spaces.
    int levels = 0;
    for (size_t p = e.paren_range.begin; p < bareBegin(e) && src_[p] == '('; p = nextToken(p + 1), ++levels)
      write("(", p, p + 1);
    bare(e);
    for (size_t p = nextToken(bareEnd(e)); levels > 0 && p < e.paren_range.end; p = nextToken(p + 1), --levels)
      write(")", p, p + 1);
  }

  void bare(const ast::Expr& e) {
    switch (e.kind) {
      case ast::ExprKind::Number:
      case ast::ExprKind::String:  // both as written: a number's spelling, a string's quotes and bytes
        write(src_.substr(e.range.begin, e.range.end - e.range.begin), e.range.begin, e.range.end);
        break;
      case ast::ExprKind::Name:
        write(e.name, e.range.begin, e.range.end);
        break;
      case ast::ExprKind::Unary: {
        write(std::string(1, e.op), e.range.begin, e.range.begin + 1);
        const ast::Expr& operand = *e.operands[0];
        if (!operand.paren_range.file && operand.kind == ast::ExprKind::Unary) raw(" ");
        expr(operand);
        break;
      }
      case ast::ExprKind::Binary: {
        expr(*e.operands[0]);
        raw(" ");
        const size_t op = nextToken(fullEnd(*e.operands[0]));
        write(std::string(1, e.op), op, op + 1);
        raw(" ");
        expr(*e.operands[1]);
        break;
      }
      case ast::ExprKind::Member: {
        const ast::Expr& operand = *e.operands[0];
        expr(operand);
        // "1 .x" stays apart: "1.x" would lex as one malformed number.
        if (!operand.paren_range.file && operand.kind == ast::ExprKind::Number &&
            src_.find_first_not_of("0123456789", operand.range.begin) >= operand.range.end)
          raw(" ");
        const size_t dot = nextToken(fullEnd(*e.operands[0]));
        write(".", dot, dot + 1);
        write(e.name, e.name_range.begin, e.name_range.end);
        break;
      }
      case ast::ExprKind::Vector: {
        write("[", e.range.begin, e.range.begin + 1);
        list(e.operands.size(), e.range.begin, e.range.end - 1,
             [&](size_t i) { return fullBegin(*e.operands[i]); },
             [&](size_t i) { expr(*e.operands[i]); });
        write("]", e.range.end - 1, e.range.end);
        break;
      }
      case ast::ExprKind::Call:
        call(e);
        break;
      case ast::ExprKind::Error:
        break;  // not reached: files with syntax errors are not formatted
    }
  }

  // The items of an argument list or vector between the opening token at
  // `open` and the closing one at `close`: on one line, or one a line when a
  // comment sits among them.
  template <class BeginOf, class Print>
  void list(size_t count, size_t open, size_t close, BeginOf begin_of, Print print) {
    if (!commentWithin(open, close)) {
      for (size_t i = 0; i < count; ++i) {
        if (i) raw(", ");
        print(i);
      }
      return;
    }
    ++indent_;
    for (size_t i = 0; i < count; ++i) {
      beginItem(begin_of(i));
      print(i);
      raw(",");
    }
    flushComments(close, false, true);
    ensureNewline();
    flushComments(close, false);
    --indent_;
    ensureNewline();
  }

  // A callee as written; `parts.tower` in its three tokens, so a comment
  // between them stays where it was.
  void callee(const ast::Expr& e) {
    const size_t split = e.name.find('.');
    if (split == std::string::npos) {
      write(e.name, e.name_range.begin, e.name_range.end);
      return;
    }
    const size_t alias_end = e.name_range.begin + split;
    write(e.name.substr(0, split), e.name_range.begin, alias_end);
    const size_t dot = nextToken(alias_end);
    write(".", dot, dot + 1);
    write(e.name.substr(split + 1), nextToken(dot + 1), e.name_range.end);
  }

  void call(const ast::Expr& e) {
    callee(e);
    const size_t open = nextToken(e.name_range.end);
    if (open < src_.size() && src_[open] == '(') {  // "union() { ... }" keeps its "()"
      size_t close = open + 1;
      if (!e.arguments.empty()) close = nextToken(fullEnd(*e.arguments.back().value));
      if (close < src_.size() && src_[close] == ',') close = nextToken(close + 1);
      if (e.arguments.empty()) close = nextToken(open + 1);
      write("(", open, open + 1);
      list(e.arguments.size(), open, close,
           [&](size_t i) {
             const ast::Argument& a = e.arguments[i];
             return a.name.empty() ? fullBegin(*a.value) : a.name_range.begin;
           },
           [&](size_t i) {
             const ast::Argument& a = e.arguments[i];
             if (!a.name.empty()) {
               write(a.name, a.name_range.begin, a.name_range.end);
               const size_t colon = nextToken(a.name_range.end);
               write(":", colon, colon + 1);
               raw(" ");
             }
             expr(*a.value);
           });
      write(")", close, close + 1);
    }
    if (e.has_block) block(e);
  }

  void block(const ast::Expr& e) {
    const size_t close = e.range.end - 1;  // the '}'
    const size_t open = nextToken(last_src_end_);  // the '{' follows the name or ')'
    raw(" ");
    write("{", open, open + 1);
    const bool has_comment = commentWithin(open, close);
    if (e.children.empty() && !has_comment) {
      write("}", close, close + 1);
      return;
    }
    if (!has_comment && !newlineBetween(open, close)) {
      for (size_t i = 0; i < e.children.size(); ++i) {
        raw(" ");
        expr(*e.children[i]);
        if (i + 1 < e.children.size() && needsSemicolon(*e.children[i + 1])) raw(";");
      }
      raw(" ");
      write("}", close, close + 1);
      return;
    }
    ++indent_;
    for (size_t i = 0; i < e.children.size(); ++i) {
      beginItem(fullBegin(*e.children[i]));
      expr(*e.children[i]);
      if (i + 1 < e.children.size() && needsSemicolon(*e.children[i + 1])) raw(";");
    }
    flushComments(close, false, true);
    ensureNewline();
    flushComments(close, false);
    --indent_;
    ensureNewline();
    write("}", close, close + 1);
  }
};

}  // namespace

std::optional<std::string> formatSource(const SourceFile& file, Diagnostics& diags) {
  std::vector<Comment> comments;
  const int errors_before = diags.errorCount();
  ast::File tree = parse(file, diags, &comments);
  if (diags.errorCount() > errors_before) return std::nullopt;
  std::string out = Printer(file, std::move(comments)).run(tree);
  // The contract checked on every run: a layout bug must never cost a user
  // their text (fmt -w and the editor write the result over the file).
  const std::string difference = tokenDifference(file, SourceFile(file.path, out));
  if (!difference.empty()) {
    diags.error({}, "internal error: formatting " + file.path + " would change its text (" + difference +
                        "); the file is left as it is");
    return std::nullopt;
  }
  return out;
}

}  // namespace sdfc
