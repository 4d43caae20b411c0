// Recursive-descent parser for grammar/sdf.ebnf. It recovers at statement
// and block boundaries, so one run reports every syntax error in a file.
#pragma once
#include "diag/diagnostics.h"
#include "syntax/ast.h"

namespace sdfc {

// Nesting deeper than this is reported, not recursed into (no stack overflow).
constexpr int kMaxNestingDepth = 200;

ast::File parse(const SourceFile& file, Diagnostics& diags);

}  // namespace sdfc
