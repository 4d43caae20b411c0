// The grammar artefacts against the compiler: grammar/sdf.ebnf must carry
// the parser's rule comments verbatim and the built-in catalogue exactly;
// grammar/sdf.tmLanguage.json must highlight exactly the catalogue's names;
// every ```sdf example in docs/language.md must check cleanly; every input
// the fuzzer once crashed on (fuzz/regressions) must now run through.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>

#include "check/builtins.h"
#include "driver/compile.h"
#include "fuzz/invariants.h"
#include "ir/expr.h"
#include "shapes/primitives.h"

namespace sdfc {
namespace {

namespace fs = std::filesystem;
using NameSet = std::set<std::string>;

std::string sourcePath(const std::string& relative) {
  return std::string(SDFC_SOURCE_DIR) + "/" + relative;
}

std::string readText(const std::string& relative) {
  std::ifstream in(sourcePath(relative), std::ios::binary);
  EXPECT_TRUE(in.good()) << "cannot read " << sourcePath(relative);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

std::vector<std::string> linesOf(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// Rules compare modulo white space: runs become one space, ends are trimmed.
std::string squeeze(const std::string& s) {
  std::string out;
  for (char c : s) {
    const bool space = c == ' ' || c == '\t' || c == '\r';
    if (space) {
      if (!out.empty() && out.back() != ' ') out += ' ';
    } else {
      out += c;
    }
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

// `// name : rhs` comments in parser.cpp. The space before ':' tells a rule
// from prose such as "// Recover: skip ...".
std::map<std::string, std::string> parserRules(const std::string& text) {
  static const std::regex kRule(R"(^\s*//\s*([a-z_]+)\s+:\s+(.*\S)\s*$)");
  std::map<std::string, std::string> rules;
  std::smatch m;
  for (const std::string& line : linesOf(text))
    if (std::regex_match(line, m, kRule)) {
      EXPECT_EQ(rules.count(m[1]), 0u) << "rule '" << m[1] << "' has two comments in parser.cpp";
      rules[m[1]] = squeeze(m[2]);
    }
  return rules;
}

// Rules of sdf.ebnf: `name : rhs` starting in column 0. Lowercase names are
// syntax (they must match the parser); uppercase ones are lexical rules and
// name lists.
std::map<std::string, std::string> ebnfRules(const std::string& text, bool syntax) {
  static const std::regex kRule(R"(^([A-Za-z_]+)\s+:\s+(.*\S)\s*$)");
  std::map<std::string, std::string> rules;
  std::smatch m;
  for (const std::string& line : linesOf(text)) {
    if (!std::regex_match(line, m, kRule)) continue;
    const std::string name = m[1];
    const bool lower = std::none_of(name.begin(), name.end(), [](char c) { return std::isupper(c); });
    if (lower != syntax) continue;
    EXPECT_EQ(rules.count(name), 0u) << "rule '" << name << "' is defined twice in sdf.ebnf";
    rules[name] = squeeze(m[2]);
  }
  return rules;
}

NameSet quotedStrings(const std::string& s) {
  static const std::regex kQuoted("\"([^\"]*)\"");
  NameSet out;
  for (std::sregex_iterator it(s.begin(), s.end(), kQuoted), end; it != end; ++it) out.insert((*it)[1]);
  return out;
}

NameSet primitiveNames() {
  NameSet out;
  for (const PrimitiveInfo& p : primitiveCatalogue()) out.insert(p.name);
  return out;
}

NameSet builtinNames(BuiltinCategory category) {
  NameSet out;
  for (const BuiltinSignature& s : builtinSignatures())
    if (s.category == category) out.insert(s.name);
  return out;
}

NameSet mathNames() {
  const std::vector<std::string>& names = ir::mathFunctionNames();
  return NameSet(names.begin(), names.end());
}

// Every callable built-in with its parameters in positional order, as the
// EBNF's comments write it: "box(size, rounding)".
std::vector<std::pair<std::string, std::vector<std::string>>> signatures() {
  std::vector<std::pair<std::string, std::vector<std::string>>> out;
  for (const PrimitiveInfo& p : primitiveCatalogue()) {
    std::vector<std::string> params;
    for (const ParamSpec& s : p.params) params.push_back(s.name);
    out.push_back({p.name, params});
  }
  for (const BuiltinSignature& b : builtinSignatures()) {
    std::vector<std::string> params;
    for (const ArgSpec& a : b.args) params.push_back(a.name);
    out.push_back({b.name, params});
  }
  return out;
}

std::string signatureText(const std::string& name, const std::vector<std::string>& params) {
  std::string s = name + "(";
  for (size_t i = 0; i < params.size(); ++i) s += (i ? ", " : "") + params[i];
  return s + ")";
}

// ---- sdf.ebnf ---------------------------------------------------------------

TEST(Grammar, EbnfSyntaxRulesAreTheParsersRuleComments) {
  const auto parser = parserRules(readText("compiler/syntax/parser.cpp"));
  const auto ebnf = ebnfRules(readText("grammar/sdf.ebnf"), true);
  // Guards the extraction itself: the parser has a rule per parse function.
  ASSERT_GE(parser.size(), 8u) << "no rule comments found in parser.cpp";
  for (const auto& [name, rhs] : parser) {
    auto it = ebnf.find(name);
    if (it == ebnf.end()) {
      ADD_FAILURE() << "parser.cpp rule '" << name << " : " << rhs << "' is missing from sdf.ebnf";
      continue;
    }
    EXPECT_EQ(it->second, rhs) << "rule '" << name << "' differs between sdf.ebnf and parser.cpp";
  }
  for (const auto& [name, rhs] : ebnf)
    EXPECT_TRUE(parser.count(name)) << "sdf.ebnf rule '" << name << "' has no rule comment in parser.cpp";
}

TEST(Grammar, EbnfRulesReferOnlyToDefinedRules) {
  const std::string text = readText("grammar/sdf.ebnf");
  auto syntax = ebnfRules(text, true);
  auto lexical = ebnfRules(text, false);
  static const std::regex kName(R"([A-Za-z_]+)");
  for (const auto& [name, rhs] : syntax) {
    // Drop quoted terminals first; what is left names rules or tokens.
    const std::string bare = std::regex_replace(rhs, std::regex("\"[^\"]*\""), " ");
    for (std::sregex_iterator it(bare.begin(), bare.end(), kName), end; it != end; ++it) {
      const std::string ref = it->str();
      EXPECT_TRUE(syntax.count(ref) || lexical.count(ref))
          << "rule '" << name << "' refers to '" << ref << "', which sdf.ebnf does not define";
    }
  }
}

TEST(Grammar, EbnfListsExactlyTheCatalogue) {
  const std::string text = readText("grammar/sdf.ebnf");
  const auto lists = ebnfRules(text, false);
  const std::map<std::string, NameSet> expected = {
      {"PRIMITIVE", primitiveNames()},
      {"OPERATOR", builtinNames(BuiltinCategory::Operator)},
      {"MATERIAL", builtinNames(BuiltinCategory::Material)},
      {"FIELD", builtinNames(BuiltinCategory::Field)},
      {"SETTING", builtinNames(BuiltinCategory::Setting)},
      {"MATH_FUNCTION", mathNames()},
      {"NAME_CONSTANT", {"time", "pi"}},
      {"SCENE", {"scene"}},
      {"MATERIAL_ARGUMENT", {"material"}},
  };
  for (const auto& [list, names] : expected) {
    auto it = lists.find(list);
    ASSERT_NE(it, lists.end()) << "sdf.ebnf has no " << list << " list";
    EXPECT_EQ(quotedStrings(it->second), names) << "sdf.ebnf's " << list << " differs from the catalogue";
  }
  // Each built-in's comment line spells its parameters in positional order.
  for (const auto& [name, params] : signatures())
    EXPECT_NE(text.find(signatureText(name, params)), std::string::npos)
        << "sdf.ebnf does not document " << signatureText(name, params);
}

TEST(Grammar, FuzzDictionaryHoldsEveryBuiltinName) {
  const NameSet dict = quotedStrings(readText("fuzz/sdf.dict"));
  NameSet names = primitiveNames();
  for (const BuiltinSignature& s : builtinSignatures()) names.insert(s.name);
  for (const std::string& f : ir::mathFunctionNames()) names.insert(f);
  for (const auto& [name, params] : signatures()) names.insert(params.begin(), params.end());
  names.insert({"let", "scene", "time", "pi", "material"});
  for (const std::string& n : names) EXPECT_TRUE(dict.count(n)) << "fuzz/sdf.dict lacks \"" << n << "\"";
}

// ---- sdf.tmLanguage.json ----------------------------------------------------

// A small TextMate engine, enough for this grammar: `match` rules with
// captures and one-level `begin`/`end` rules, includes resolved from the
// repository, the leftmost match winning and ties going to the earlier rule.
class TextMate {
 public:
  explicit TextMate(const nlohmann::json& grammar) : grammar_(grammar) {
    for (const auto& p : grammar.at("patterns")) add(p);
  }

  // The innermost scope of every byte of a (multi-line) text.
  std::vector<std::string> scopes(const std::string& text) const {
    std::vector<std::string> out(text.size());
    const Rule* open = nullptr;  // an unfinished begin/end rule
    size_t line_start = 0;
    while (line_start <= text.size()) {
      size_t line_end = text.find('\n', line_start);
      if (line_end == std::string::npos) line_end = text.size();
      const std::string line = text.substr(line_start, line_end - line_start);
      size_t pos = 0;
      while (pos < line.size()) {
        if (open) {
          std::smatch m;
          const bool closes = search(open->end, line, pos, m);
          const size_t stop = closes ? pos + m.position(0) + m.length(0) : line.size();
          for (size_t i = pos; i < stop; ++i) out[line_start + i] = open->scope;
          if (closes) open = nullptr;
          pos = stop;
          continue;
        }
        const Rule* best = nullptr;
        std::smatch best_m;
        size_t best_at = line.size();
        for (const Rule& r : rules_) {
          std::smatch m;
          if (!search(r.is_begin ? r.begin : r.match, line, pos, m)) continue;
          const size_t at = pos + m.position(0);
          if (at < best_at) best = &r, best_m = m, best_at = at;
        }
        if (!best) break;
        const size_t length = std::max<size_t>(best_m.length(0), 1);
        for (size_t i = 0; i < length && best_at + i < line.size(); ++i)
          out[line_start + best_at + i] = best->scope;
        for (const auto& [group, scope] : best->captures) {
          if (group >= best_m.size() || !best_m[group].matched) continue;
          for (long i = 0; i < best_m.length(group); ++i) out[line_start + pos + best_m.position(group) + i] = scope;
        }
        if (best->is_begin) open = best;
        pos = best_at + length;
      }
      line_start = line_end + 1;
    }
    return out;
  }

  // Scope of the first character of the first occurrence of `word` in `line`.
  std::string scopeOf(const std::string& line, const std::string& word) const {
    const size_t at = line.find(word);
    if (at == std::string::npos) return "<not in line>";
    return scopes(line)[at];
  }

 private:
  struct Rule {
    std::string scope;
    std::regex match, begin, end;
    bool is_begin = false;
    std::map<size_t, std::string> captures;
  };
  const nlohmann::json& grammar_;
  std::vector<Rule> rules_;

  static bool search(const std::regex& re, const std::string& line, size_t pos, std::smatch& m) {
    auto flags = std::regex_constants::match_default;
    if (pos > 0) flags |= std::regex_constants::match_prev_avail;  // \b sees the previous byte
    return std::regex_search(line.begin() + static_cast<long>(pos), line.end(), m, re, flags);
  }

  void add(const nlohmann::json& p) {
    if (p.contains("include")) {
      const std::string ref = p.at("include").get<std::string>().substr(1);  // "#name"
      for (const auto& q : grammar_.at("repository").at(ref).at("patterns")) add(q);
      return;
    }
    Rule r;
    r.scope = p.value("name", "");
    if (p.contains("match")) {
      r.match = std::regex(p.at("match").get<std::string>());
    } else {
      r.is_begin = true;
      r.begin = std::regex(p.at("begin").get<std::string>());
      r.end = std::regex(p.at("end").get<std::string>());
    }
    if (p.contains("captures"))
      for (const auto& [group, c] : p.at("captures").items()) r.captures[std::stoul(group)] = c.at("name");
    rules_.push_back(std::move(r));
  }
};

nlohmann::json loadTextMate() {
  return nlohmann::json::parse(readText("grammar/sdf.tmLanguage.json"));  // throws on bad JSON
}

// The words of a `\b(a|b|c)\b` match.
NameSet alternation(const std::string& match) {
  NameSet out;
  const size_t open = match.find('('), close = match.rfind(')');
  if (open == std::string::npos || close == std::string::npos) return out;
  std::istringstream in(match.substr(open + 1, close - open - 1));
  for (std::string word; std::getline(in, word, '|');) out.insert(word);
  return out;
}

TEST(Grammar, TextMateListsExactlyTheCatalogue) {
  const nlohmann::json g = loadTextMate();
  EXPECT_EQ(g.at("scopeName"), "source.sdf");
  std::map<std::string, NameSet> lists;
  for (const auto& p : g.at("repository").at("builtins").at("patterns"))
    lists[p.at("name")] = alternation(p.at("match"));
  EXPECT_EQ(lists["support.function.primitive.sdf"], primitiveNames());
  EXPECT_EQ(lists["support.function.operator.sdf"], builtinNames(BuiltinCategory::Operator));
  EXPECT_EQ(lists["support.type.material.sdf"], builtinNames(BuiltinCategory::Material));
  EXPECT_EQ(lists["support.function.field.sdf"], builtinNames(BuiltinCategory::Field));
  EXPECT_EQ(lists["support.function.setting.sdf"], builtinNames(BuiltinCategory::Setting));
  EXPECT_EQ(lists["support.function.math.sdf"], mathNames());
  EXPECT_EQ(lists["constant.language.sdf"], (NameSet{"time", "pi"}));
}

TEST(Grammar, TextMateHighlightsEachKindOfToken) {
  const nlohmann::json g = loadTextMate();
  const TextMate tm(g);
  const std::string line = "let clay = diffuse(albedo: [0.8, .3, 2.5e-1]) // a comment";
  EXPECT_EQ(tm.scopeOf(line, "let"), "keyword.other.let.sdf");
  EXPECT_EQ(tm.scopeOf(line, "clay"), "entity.name.variable.sdf");
  EXPECT_EQ(tm.scopeOf(line, "="), "keyword.operator.assignment.sdf");
  EXPECT_EQ(tm.scopeOf(line, "diffuse"), "support.type.material.sdf");
  EXPECT_EQ(tm.scopeOf(line, "albedo"), "variable.parameter.sdf");
  EXPECT_EQ(tm.scopeOf(line, ":"), "punctuation.separator.key-value.sdf");
  EXPECT_EQ(tm.scopeOf(line, "["), "punctuation.section.brackets.begin.sdf");
  EXPECT_EQ(tm.scopeOf(line, "0.8"), "constant.numeric.sdf");
  EXPECT_EQ(tm.scopeOf(line, ".3"), "constant.numeric.sdf");
  EXPECT_EQ(tm.scopeOf(line, "e-1"), "constant.numeric.sdf");
  EXPECT_EQ(tm.scopeOf(line, ","), "punctuation.separator.comma.sdf");
  EXPECT_EQ(tm.scopeOf(line, "// a"), "comment.line.double-slash.sdf");
  EXPECT_EQ(tm.scopeOf(line, "comment"), "comment.line.double-slash.sdf");

  const std::string scene = "scene { union(smooth: 0.1) { sphere(radius: r * sin(time)) } } /* x\ny */ 2x $";
  EXPECT_EQ(tm.scopeOf(scene, "scene"), "keyword.other.scene.sdf");
  EXPECT_EQ(tm.scopeOf(scene, "union"), "support.function.operator.sdf");
  EXPECT_EQ(tm.scopeOf(scene, "smooth"), "variable.parameter.sdf");
  EXPECT_EQ(tm.scopeOf(scene, "sphere"), "support.function.primitive.sdf");
  EXPECT_EQ(tm.scopes(scene)[scene.find(" r ") + 1], "variable.other.sdf");
  EXPECT_EQ(tm.scopeOf(scene, "*"), "keyword.operator.arithmetic.sdf");
  EXPECT_EQ(tm.scopeOf(scene, "sin"), "support.function.math.sdf");
  EXPECT_EQ(tm.scopeOf(scene, "time"), "constant.language.sdf");
  EXPECT_EQ(tm.scopeOf(scene, "{"), "punctuation.section.block.begin.sdf");
  EXPECT_EQ(tm.scopeOf(scene, "x\n"), "comment.block.sdf");
  EXPECT_EQ(tm.scopeOf(scene, "y */"), "comment.block.sdf");
  EXPECT_EQ(tm.scopeOf(scene, "2x"), "invalid.illegal.number.sdf");
  // Numbers end where the lexer ends them.
  EXPECT_EQ(tm.scopes("1e")[1], "invalid.illegal.number.sdf");
  EXPECT_EQ(tm.scopes("2.5e+3")[5], "constant.numeric.sdf");
  EXPECT_EQ(tm.scopes("1.5.x")[4], "invalid.illegal.number.sdf");
  EXPECT_EQ(tm.scopes("x2")[1], "variable.other.sdf");
  EXPECT_EQ(tm.scopes("v.x")[1], "punctuation.accessor.sdf");
  EXPECT_EQ(tm.scopeOf(scene, "$"), "invalid.illegal.character.sdf");

  // Every built-in, used as a call, gets its category's scope.
  auto expectScope = [&](const std::string& name, const std::string& scope) {
    EXPECT_EQ(tm.scopeOf(name + "(1)", name), scope) << name;
  };
  for (const std::string& n : primitiveNames()) expectScope(n, "support.function.primitive.sdf");
  for (const std::string& n : builtinNames(BuiltinCategory::Operator)) expectScope(n, "support.function.operator.sdf");
  for (const std::string& n : builtinNames(BuiltinCategory::Material)) expectScope(n, "support.type.material.sdf");
  for (const std::string& n : builtinNames(BuiltinCategory::Field)) expectScope(n, "support.function.field.sdf");
  for (const std::string& n : builtinNames(BuiltinCategory::Setting)) expectScope(n, "support.function.setting.sdf");
  for (const std::string& n : mathNames()) expectScope(n, "support.function.math.sdf");
  // A user name that merely starts like a built-in is not one.
  EXPECT_EQ(tm.scopeOf("let spheres = 1", "spheres"), "entity.name.variable.sdf");
  EXPECT_EQ(tm.scopeOf("spheres", "spheres"), "variable.other.sdf");
  // Parametric definitions and imports.
  const std::string def = "let tower(height, radius: 1) = parts.post(height)";
  EXPECT_EQ(tm.scopeOf(def, "tower"), "entity.name.variable.sdf");
  EXPECT_EQ(tm.scopeOf(def, "radius"), "variable.parameter.sdf");
  EXPECT_EQ(tm.scopeOf(def, "parts"), "variable.other.sdf");
  const std::string import = "import \"my parts.sdf\" as lib";
  EXPECT_EQ(tm.scopeOf(import, "import"), "keyword.other.import.sdf");
  EXPECT_EQ(tm.scopeOf(import, "my parts"), "string.quoted.double.sdf");
  EXPECT_EQ(tm.scopeOf(import, "as"), "keyword.other.import.sdf");
  EXPECT_EQ(tm.scopeOf(import, "lib"), "entity.name.namespace.sdf");
}

// ---- docs/language.md -------------------------------------------------------

struct Snippet {
  int line;  // of the opening fence, 1-based
  std::string text;
};

std::vector<Snippet> docSnippets() {
  std::vector<Snippet> out;
  const std::vector<std::string> lines = linesOf(readText("docs/language.md"));
  for (size_t i = 0; i < lines.size(); ++i) {
    if (squeeze(lines[i]) != "```sdf") continue;
    Snippet s{static_cast<int>(i) + 1, ""};
    for (++i; i < lines.size() && squeeze(lines[i]) != "```"; ++i) s.text += lines[i] + "\n";
    out.push_back(s);
  }
  return out;
}

TEST(Grammar, EveryDocExampleChecksWithoutErrors) {
  const std::vector<Snippet> snippets = docSnippets();
  ASSERT_GE(snippets.size(), 10u) << "docs/language.md lost its ```sdf examples";
  for (const Snippet& s : snippets) {
    Diagnostics diags;
    // Beside the page, so a file an example reads is found from docs/.
    const std::string name = std::string(SDFC_SOURCE_DIR) + "/docs/language.md:" + std::to_string(s.line);
    CompiledScene compiled = checkSource(name, s.text, CompileOptions{}, diags);
    EXPECT_FALSE(diags.hasErrors()) << "the example at docs/language.md line " << s.line
                                    << " does not check:\n" << diags.format() << s.text;
    EXPECT_TRUE(compiled.ok) << name;
  }
}

TEST(Grammar, DocsShowEveryBuiltinAndParameter) {
  std::string examples;
  for (const Snippet& s : docSnippets()) examples += s.text;
  const std::string doc = readText("docs/language.md");
  auto used = [&](const std::string& name) {
    return std::regex_search(examples, std::regex("\\b" + name + "\\b"));
  };
  for (const auto& [name, params] : signatures()) {
    EXPECT_TRUE(used(name)) << "no checked example in docs/language.md uses '" << name << "'";
    for (const std::string& p : params)
      EXPECT_NE(doc.find("`" + p + "`"), std::string::npos)
          << "docs/language.md never names parameter `" << p << "` of " << name;
  }
  for (const std::string& f : ir::mathFunctionNames())
    EXPECT_TRUE(used(f)) << "no checked example in docs/language.md uses '" << f << "'";
  for (const char* n : {"time", "pi", "let", "scene", "material"})
    EXPECT_TRUE(used(n)) << "no checked example in docs/language.md uses '" << n << "'";
}

TEST(Grammar, DocExampleCheckerCatchesABrokenExample) {
  // The doc test above must be able to fail: a broken snippet is an error.
  Diagnostics diags;
  checkSource("broken.sdf", "scene { sphere(radius: -1) }\n", CompileOptions{}, diags);
  EXPECT_TRUE(diags.hasErrors());
}

// ---- fuzz/ ------------------------------------------------------------------

std::vector<fs::path> inputsUnder(const std::string& relative) {
  std::vector<fs::path> out;
  const fs::path dir = sourcePath(relative);
  if (!fs::is_directory(dir)) return out;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.is_regular_file() && entry.path().filename().string().rfind("README", 0) != 0)
      out.push_back(entry.path());
  std::sort(out.begin(), out.end());
  return out;
}

// Runs one input the way the fuzz target does; a crash fails the whole binary.
void runLikeTheFuzzer(const fs::path& path, bool check_finite) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  Diagnostics diags;
  CompiledScene compiled = checkSource(path.filename().string(), bytes.str(), CompileOptions{}, diags);
  (void)diags.format();
  (void)diags.formatJson();
  EXPECT_EQ(fuzz::violatedInvariant(compiled, diags, check_finite), "") << path;
}

TEST(Grammar, FuzzRegressionsRunWithoutCrashing) {
  const std::vector<fs::path> inputs = inputsUnder("fuzz/regressions");
  ASSERT_FALSE(inputs.empty()) << "fuzz/regressions has no inputs";
  for (const fs::path& p : inputs) {
    SCOPED_TRACE(p.string());
    runLikeTheFuzzer(p, false);
  }
}

// Disabled until the checker rejects non-finite constants (inf and NaN from
// arithmetic overflow, fuzz/regressions/nonfinite_*.sdf); then enable it and
// make SDFC_FUZZ_FINITE the fuzz target's default.
TEST(Grammar, FuzzRegressionsCheckToFiniteScenes) {
  for (const fs::path& p : inputsUnder("fuzz/regressions")) {
    SCOPED_TRACE(p.string());
    runLikeTheFuzzer(p, true);
  }
}

TEST(Grammar, FuzzSeedCorpusRunsWithoutCrashing) {
  const std::vector<fs::path> inputs = inputsUnder("fuzz/corpus");
  ASSERT_FALSE(inputs.empty()) << "fuzz/corpus has no seeds";
  for (const fs::path& p : inputs) {
    SCOPED_TRACE(p.string());
    runLikeTheFuzzer(p, false);
  }
}

}  // namespace
}  // namespace sdfc
