// The formatter's contract as a check: formatted text holds the same tokens
// and comments as its source, in the same order, and only the white space
// between them differs. Two kinds of punctuation the layout rules normalise
// are not counted: a ';' the parser ignores (one not before '(' or '-', where
// it would keep the next item from gluing on) and a trailing ',' before ')'
// or ']'; and a comment may move across a ',' or ';'. formatSource runs it on
// every result; the tests run it on corpora.
#pragma once
#include <string>

#include "diag/source.h"

namespace sdfc {

// "" when `before` and `after` agree; otherwise the first difference, as
// "'file(\"p.csv\")' became 'file()'"-like text with both line numbers.
std::string tokenDifference(const SourceFile& before, const SourceFile& after);

}  // namespace sdfc
