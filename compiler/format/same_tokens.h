// The formatter's contract as a check: formatted text holds the same tokens
// and comments as its source, in the same order, and only the white space
// between them differs. Two kinds of punctuation the layout rules normalise
// are not counted, ';' and a trailing ',' before ')' or ']', and a comment may
// move across a ',' or ';'; so that a dropped ';' cannot glue two items into
// one ("a; (b)" into the call "a (b)"), both texts' parse trees must also
// have the same shape. formatSource runs it on every result; the tests run it
// on corpora.
#pragma once
#include <string>

#include "diag/source.h"

namespace sdfc {

// "" when `before` and `after` agree; otherwise the first difference, as
// "'file(\"p.csv\")' became 'file()'"-like text with both line numbers.
std::string tokenDifference(const SourceFile& before, const SourceFile& after);

// The parse tree's shape as text (statements, expression kinds, operators,
// names and how they nest), "" when `file` does not parse.
std::string syntaxShape(const SourceFile& file);

}  // namespace sdfc
