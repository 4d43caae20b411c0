// `import "parts.sdf"` and `import "parts.sdf" as parts`: reads and parses
// the imported files (paths relative to the importing file, transitively),
// reports cycles, missing files and statements other than definitions, and
// lists the definitions each brings in under its prefix ("" or "parts.").
// The checker binds them; diagnostics inside a file name that file.
#pragma once
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "diag/diagnostics.h"
#include "syntax/ast.h"

namespace sdfc {

struct ImportedDefinition {
  const ast::Statement* statement;
  // The namespace it is bound in ("parts." for `as parts`; nested imports
  // add up, "a.b."), and the namespace its own body looks names up in.
  std::string prefix;
  // How it came in, for clashes: "'parts.sdf', imported at castle.sdf:3:1".
  std::string via;
  const ast::Statement* import;  // the import statement (in the importing file) that brought it
};

struct ImportSet {
  std::vector<std::shared_ptr<SourceFile>> files;  // every imported file, once
  std::vector<std::unique_ptr<ast::File>> trees;
  std::vector<ImportedDefinition> definitions;
  // The files each file imports: a body in a file sees the names of the
  // file and of these, transitively (under their prefixes), nothing else.
  std::map<const SourceFile*, std::vector<const SourceFile*>> edges;
};

// Imports are nested at most this deep (a chain, not a cycle, of files).
constexpr int kMaxImportDepth = 50;

ImportSet loadImports(const ast::File& file, const SourceFile& source, Diagnostics& diags);

}  // namespace sdfc
