// The hand-written lexer: source text to tokens. Bad characters and
// malformed numbers become diagnostics and Invalid tokens; it never stops early.
#pragma once
#include <vector>

#include "diag/diagnostics.h"
#include "syntax/token.h"

namespace sdfc {

// Always ends with an EndOfFile token.
// Comments are appended to `comments` when it is given, in source order.
std::vector<Token> lex(const SourceFile& file, Diagnostics& diags,
                       std::vector<Comment>* comments = nullptr);

}  // namespace sdfc
