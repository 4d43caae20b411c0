// Warnings turned off inside a scene, by comments the lexer keeps:
//   // sdfc: allow(bound, unused)   on its own line: the next statement or
//                                   expression (a whole call with its block);
//                                   after code: what begins first on that line
//   // sdfc: allow-file(bound)      the whole file
// (docs/language.md, "Warnings"). Unknown names are a warning themselves.
#pragma once
#include <vector>

#include "diag/diagnostics.h"
#include "syntax/ast.h"
#include "syntax/token.h"

namespace sdfc {

void applyWarningPragmas(const ast::File& file, const SourceFile& source,
                         const std::vector<Comment>& comments, Diagnostics& diags);

}  // namespace sdfc
