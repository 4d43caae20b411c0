// Recursive-descent parser for grammar/sdf.ebnf. It recovers at statement
// and block boundaries, so one run reports every syntax error in a file.
#pragma once
#include "diag/diagnostics.h"
#include "syntax/ast.h"
#include "syntax/token.h"

namespace sdfc {

// Nesting deeper than this is reported, not recursed into (no stack overflow).
constexpr int kMaxNestingDepth = 200;

// `comments`, when given, receives the comments the lexer skipped.
ast::File parse(const SourceFile& file, Diagnostics& diags,
                std::vector<Comment>* comments = nullptr);

}  // namespace sdfc
