// sdfc fmt's layout rules (compiler/format), case by case; tests/fmt_test.py
// checks the examples, docs and fuzz corpus as a whole.
#include <gtest/gtest.h>

#include "format/formatter.h"

namespace sdfc {
namespace {

std::string fmt(const std::string& text) {
  SourceFile file("test.sdf", text);
  Diagnostics diags;
  std::optional<std::string> out = formatSource(file, diags);
  EXPECT_TRUE(out.has_value()) << diags.format();
  if (!out) return "";
  SourceFile again("test.sdf", *out);
  Diagnostics diags2;
  EXPECT_EQ(formatSource(again, diags2).value_or("<error>"), *out) << "not idempotent";
  return *out;
}

TEST(Format, SpacingIsCanonical) {
  EXPECT_EQ(fmt("scene{sphere( radius:1 )}"), "scene { sphere(radius: 1) }\n");
  EXPECT_EQ(fmt("let  a=1+2*3\ncamera(position:[0,1,2],fov:40)"),
            "let a = 1 + 2 * 3\ncamera(position: [0, 1, 2], fov: 40)\n");
}

TEST(Format, MultiLineBlocksIndentAndKeepOneBlankLine) {
  EXPECT_EQ(fmt("scene {\n\n\nsphere(radius: 1)\n\n\n\nbox(size: [1, 1, 1])\n\n}\n"),
            "scene {\n  sphere(radius: 1)\n\n  box(size: [1, 1, 1])\n}\n");
}

TEST(Format, KeepsEveryComment) {
  const std::string out = fmt("// head\nlet a = 1 // trailing\n/* block */ scene { sphere(radius: a) } // end\n");
  EXPECT_NE(out.find("// head"), std::string::npos);
  EXPECT_NE(out.find("let a = 1  // trailing"), std::string::npos);
  EXPECT_NE(out.find("/* block */"), std::string::npos);
  EXPECT_NE(out.find("// end"), std::string::npos);
}

TEST(Format, AlignsTrailingCommentsOnConsecutiveLines) {
  EXPECT_EQ(fmt("let a = 1 // x\nlet long_name = 2 // y\n"),
            "let a = 1          // x\nlet long_name = 2  // y\n");
}

TEST(Format, CommentInsideArgumentsBreaksThemOneALine) {
  EXPECT_EQ(fmt("camera(fov: 40, // wide\n  position: [0, 1, 2])"),
            "camera(\n  fov: 40,  // wide\n  position: [0, 1, 2],\n)\n");
}

TEST(Format, SemicolonOnlyWhereTheNextItemWouldGlueOn) {
  EXPECT_EQ(fmt("let a = b; (c)\nlet d = 1;"), "let a = b;\n(c)\nlet d = 1\n");
  EXPECT_EQ(fmt("scene { union { sphere(radius: 1); -x } }"), "scene { union { sphere(radius: 1); -x } }\n");
  EXPECT_EQ(fmt("let a = 1;\nlet b = (2)"), "let a = 1\nlet b = (2)\n");
}

TEST(Format, ParenthesesAndNumbersAsWritten) {
  EXPECT_EQ(fmt("let a = ((1 + 2)) * .5e1 - (3)"), "let a = (1 + 2) * .5e1 - (3)\n");
  EXPECT_EQ(fmt("let a = - -1"), "let a = - -1\n");
}

TEST(Format, RefusesFilesWithSyntaxErrors) {
  SourceFile file("bad.sdf", "scene { sphere(radius: ) ");
  Diagnostics diags;
  EXPECT_FALSE(formatSource(file, diags).has_value());
  EXPECT_TRUE(diags.hasErrors());
}

}  // namespace
}  // namespace sdfc
