// The canonical layout of a .sdf file (`sdfc fmt`, the editor's "format
// document"). It prints the parse tree, so the result has one layout whatever
// the input's spacing, and it carries every comment across. Idempotent:
// formatting formatted text changes nothing.
#pragma once
#include <optional>
#include <string>

#include "diag/diagnostics.h"

namespace sdfc {

// The formatted text, or nullopt when the file has syntax errors (reported to
// `diags`; a file that does not parse is never rewritten).
std::optional<std::string> formatSource(const SourceFile& file, Diagnostics& diags);

}  // namespace sdfc
