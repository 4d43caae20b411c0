// Recursive-descent parser for grammar/sdf.ebnf. It recovers at statement
// and block boundaries, so one run reports every syntax error in a file.
#pragma once
#include "diag/diagnostics.h"
#include "syntax/ast.h"
#include "syntax/token.h"

namespace sdfc {

// Nesting (parentheses, brackets, blocks, calls, unary minus) deeper than
// this is reported, not recursed into (no stack overflow in the parser).
constexpr int kMaxNestingDepth = 200;
// The checker, evaluator and emitter recurse over expression trees, and an
// operator chain `a + b + c` is a tree one level deeper per operator: a tree
// taller than this is reported (a flat sum may have up to ~1000 terms).
constexpr int kMaxExpressionHeight = 1000;

// `comments`, when given, receives the comments the lexer skipped.
ast::File parse(const SourceFile& file, Diagnostics& diags,
                std::vector<Comment>* comments = nullptr);

}  // namespace sdfc
