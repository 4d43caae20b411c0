// Parser and diagnostics: the printed form of every syntax error is pinned.
#include <gtest/gtest.h>

#include "syntax/parser.h"

namespace sdfc {
namespace {

std::string diagnosticsFor(const std::string& text) {
  SourceFile file("t.sdf", text);
  Diagnostics diags;
  parse(file, diags);
  return diags.format();
}

TEST(Parser, AcceptsCallsBlocksAndExpressions) {
  SourceFile file("t.sdf",
                  "let r = 1 + 2 * 3 // comment\n"
                  "scene { translate([1, -r, 0.5e1]) { sphere(radius: r / 2) } }\n");
  Diagnostics diags;
  ast::File ast = parse(file, diags);
  EXPECT_FALSE(diags.hasErrors()) << diags.format();
  ASSERT_EQ(ast.statements.size(), 2u);
  EXPECT_TRUE(ast.statements[0].is_let);
  const ast::Expr& scene = *ast.statements[1].value;
  EXPECT_EQ(scene.kind, ast::ExprKind::Call);
  ASSERT_EQ(scene.children.size(), 1u);
  EXPECT_EQ(scene.children[0]->name, "translate");
  EXPECT_EQ(scene.children[0]->arguments.size(), 1u);
}

TEST(Parser, ReportsWithLineColumnAndCaret) {
  EXPECT_EQ(diagnosticsFor("scene { sphere(radius: ) }\n"),
            "t.sdf:1:24: error: expected an expression, found ')'\n"
            "scene { sphere(radius: ) }\n"
            "                       ^\n");
}

TEST(Parser, ReportsEveryErrorNotJustTheFirst) {
  const std::string out = diagnosticsFor("let a = 2x\nlet = 3\nscene { box(size: $) }\n");
  EXPECT_NE(out.find("t.sdf:1:9: error: malformed number '2x'"), std::string::npos) << out;
  EXPECT_NE(out.find("t.sdf:2:5: error: expected identifier after 'let', found '='"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("t.sdf:3:19: error: unexpected character '$'"), std::string::npos) << out;
}

TEST(Parser, UnclosedBlockPointsAtItsOpening) {
  const std::string out = diagnosticsFor("scene {\n  sphere(radius: 1)\n");
  EXPECT_NE(out.find("error: expected '}' to close the block"), std::string::npos) << out;
  EXPECT_NE(out.find("t.sdf:1:7: note: the block opens here"), std::string::npos) << out;
}

TEST(Parser, DeepNestingIsAnErrorNotACrash) {
  std::string text = "let x = " + std::string(100000, '(') + "1" + std::string(100000, ')');
  const std::string out = diagnosticsFor(text);
  EXPECT_NE(out.find("nesting is deeper than 200 levels"), std::string::npos);
  std::string minus = "let y = " + std::string(100000, '-') + "1";
  EXPECT_NE(diagnosticsFor(minus).find("nesting is deeper"), std::string::npos);
  std::string blocks;
  for (int i = 0; i < 50000; ++i) blocks += "union {";
  EXPECT_NE(diagnosticsFor("scene {" + blocks).find("nesting is deeper"), std::string::npos);
}

TEST(Parser, RandomBytesGiveErrorsNeverACrash) {
  std::uint32_t state = 12345;
  for (int round = 0; round < 200; ++round) {
    std::string text;
    for (int i = 0; i < 300; ++i) {
      state = state * 1664525u + 1013904223u;
      text += static_cast<char>(state >> 24);
    }
    SourceFile file("r.sdf", text);
    Diagnostics diags;
    parse(file, diags);
    (void)diags.format();
  }
  SUCCEED();
}

}  // namespace
}  // namespace sdfc
