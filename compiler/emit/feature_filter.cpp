#include "emit/feature_filter.h"

#include <regex>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace sdfc {
namespace {

std::string trimBlanks(std::string_view s) {
  size_t b = s.find_first_not_of(" \t\r");
  if (b == std::string_view::npos) return "";
  size_t e = s.find_last_not_of(" \t\r");
  return std::string(s.substr(b, e - b + 1));
}

struct Frame {
  bool ours;        // an SDFC_ conditional (resolved here) or a foreign one (passed on)
  bool parent_on;   // were lines being kept when it opened
  bool condition;   // value of the condition (ours only)
  bool in_else = false;
};

}  // namespace

std::string filterFeatures(std::string_view text, const std::set<std::string>& defined) {
  static const std::regex kDefinedTerm(R"(defined\s*\(\s*(\w+)\s*\))");
  std::vector<Frame> stack;
  std::ostringstream out;
  bool on = true;
  std::istringstream in{std::string(text)};
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const std::string t = trimBlanks(line);
    auto fail = [&](const std::string& why) {
      throw std::runtime_error("kernel line " + std::to_string(number) + ": " + why);
    };
    if (t.rfind("#if", 0) == 0) {
      std::string cond = trimBlanks(std::string_view(t).substr(t.find_first_of(" \t") == std::string::npos
                                                             ? t.size()
                                                             : t.find_first_of(" \t")));
      const bool is_ifdef = t.rfind("#ifdef", 0) == 0, is_ifndef = t.rfind("#ifndef", 0) == 0;
      if ((is_ifdef || is_ifndef) && cond.rfind("SDFC_", 0) == 0) {
        const bool v = defined.count(cond) > 0;
        stack.push_back({true, on, is_ifdef ? v : !v});
        on = on && stack.back().condition;
        continue;
      }
      if (!is_ifdef && !is_ifndef && cond.find("SDFC_") != std::string::npos) {
        // Only disjunctions of defined(SDFC_X) are supported.
        bool value = false;
        std::string rest = cond;
        std::smatch m;
        int terms = 0;
        while (std::regex_search(rest, m, kDefinedTerm)) {
          value = value || defined.count(m[1].str()) > 0;
          rest = m.prefix().str() + m.suffix().str();
          ++terms;
        }
        for (char c : rest)
          if (c != '|' && c != ' ' && c != '\t') fail("unsupported feature condition: " + t);
        if (terms == 0) fail("unsupported feature condition: " + t);
        stack.push_back({true, on, value});
        on = on && value;
        continue;
      }
      stack.push_back({false, on, true});
      if (on) out << line << "\n";
      continue;
    }
    if (t.rfind("#else", 0) == 0) {
      if (stack.empty()) fail("#else without #if");
      Frame& f = stack.back();
      if (f.in_else) fail("second #else");
      f.in_else = true;
      if (f.ours) {
        on = f.parent_on && !f.condition;
      } else if (f.parent_on) {
        out << line << "\n";
      }
      continue;
    }
    if (t.rfind("#elif", 0) == 0) {
      if (!stack.empty() && stack.back().ours) fail("#elif is not supported in feature blocks");
      if (on || (!stack.empty() && stack.back().parent_on)) out << line << "\n";
      continue;
    }
    if (t.rfind("#endif", 0) == 0) {
      if (stack.empty()) fail("#endif without #if");
      const Frame f = stack.back();
      stack.pop_back();
      on = f.parent_on;
      if (!f.ours && on) out << line << "\n";
      continue;
    }
    if (on) out << line << "\n";
  }
  if (!stack.empty()) throw std::runtime_error("unterminated #if in kernel");
  return out.str();
}

}  // namespace sdfc
