#include "syntax/pragmas.h"

#include <algorithm>
#include <cctype>

#include "diag/warnings.h"

namespace sdfc {
namespace {

struct Span {
  size_t begin, end;
};

void collect(const ast::Expr& e, std::vector<Span>& out) {
  out.push_back({e.range.begin, e.range.end});
  for (const ast::ExprPtr& o : e.operands) collect(*o, out);
  for (const ast::Argument& a : e.arguments) collect(*a.value, out);
  for (const ast::ExprPtr& c : e.children) collect(*c, out);
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

// The names in "allow(a, b)" after "sdfc:", or false when the comment is
// not of that form.
bool parsePragma(std::string_view body, bool& whole_file, std::vector<std::string>& names) {
  body = trim(body);
  for (std::string_view keyword : {"allow-file(", "allow("}) {
    if (body.substr(0, keyword.size()) != keyword || body.back() != ')') continue;
    whole_file = keyword == "allow-file(";
    std::string_view list = body.substr(keyword.size(), body.size() - keyword.size() - 1);
    while (!list.empty()) {
      const size_t comma = list.find(',');
      const std::string_view name = trim(list.substr(0, comma));
      if (!name.empty()) names.emplace_back(name);
      if (comma == std::string_view::npos) break;
      list.remove_prefix(comma + 1);
    }
    return !names.empty();
  }
  return false;
}

}  // namespace

void applyWarningPragmas(const ast::File& file, const SourceFile& source,
                         const std::vector<Comment>& comments, Diagnostics& diags) {
  std::vector<Span> spans;
  bool collected = false;
  for (const Comment& c : comments) {
    std::string_view body(source.text.data() + c.range.begin, c.range.end - c.range.begin);
    body.remove_prefix(2);                                           // "//" or "/*"
    if (!c.line_comment && body.size() >= 2) body.remove_suffix(2);  // "*/"
    body = trim(body);
    constexpr std::string_view kPrefix = "sdfc:";
    if (body.substr(0, kPrefix.size()) != kPrefix) continue;
    bool whole_file = false;
    std::vector<std::string> names;
    if (!parsePragma(body.substr(kPrefix.size()), whole_file, names)) {
      diags.warning(c.range, "unknown-warning",
                    "a comment starting 'sdfc:' is read as a pragma: write 'sdfc: allow(NAME, ...)' "
                    "or 'sdfc: allow-file(NAME, ...)'");
      continue;
    }
    if (!collected) {
      for (const ast::Statement& s : file.statements) {
        spans.push_back({s.range.begin, s.range.end});
        if (s.value) collect(*s.value, spans);
      }
      collected = true;
    }
    SourceRange region{&source, 0, source.text.size() + 1};
    if (!whole_file) {
      // Trailing a line of code: the outermost thing that begins on that line
      // before the comment; on a line of its own: the next thing after it.
      const size_t line_begin = source.lineStart(source.lineColumn(c.range.begin).first);
      const bool trailing = trim(std::string_view(source.text).substr(
                                line_begin, c.range.begin - line_begin)).size() > 0;
      const Span* best = nullptr;
      for (const Span& s : spans) {
        const bool fits = trailing ? s.begin >= line_begin && s.begin < c.range.begin
                                   : s.begin >= c.range.end;
        if (!fits) continue;
        if (!best || s.begin < best->begin || (s.begin == best->begin && s.end > best->end)) best = &s;
      }
      // Nothing follows: nothing to allow (an empty region; names still checked).
      region.begin = best ? best->begin : 0;
      region.end = best ? std::max(best->end, best->begin + 1) : 0;
    }
    for (const std::string& name : names) {
      if (isWarningName(name)) {
        diags.allowIn(region, name);
        continue;
      }
      std::string message = "no warning is named '" + name + "'";
      const std::string near = nearestName(name, warningNames());
      if (!near.empty()) message += "; did you mean '" + near + "'?";
      diags.warning(c.range, "unknown-warning", message);
    }
  }
}

}  // namespace sdfc
