// `import "parts.sdf"` and `import "parts.sdf" as parts`: reads and parses
// the imported files (paths relative to the importing file, transitively),
// reports cycles, missing files and statements other than definitions, and
// lists the definitions each brings in under its prefix ("" or "parts.").
// The checker binds them; diagnostics inside a file name that file.
#pragma once
#include <functional>
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

// Each file's definitions are bound once, under the prefix it is first
// reached with; another way to it is an alias. `from` + "name" means `to` +
// "name": `import "b.sdf" as y` where b.sdf is bound as "x." gives "y." ->
// "x."; an import without `as` of an already bound file gives "" -> "x.".
// (Binding each file under every prefix it is reached by was exponential: N
// files each importing the next twice made 2^N copies.)
struct ImportAlias {
  std::string from, to;
  const ast::Statement* import;  // the first import statement that made it
  std::string via;               // "'parts.sdf', imported at castle.sdf:3:1"
};

struct ImportSet {
  std::vector<std::shared_ptr<SourceFile>> files;  // every imported file, once
  std::vector<std::unique_ptr<ast::File>> trees;
  std::vector<ImportedDefinition> definitions;  // each file's once, under its first prefix
  std::map<std::string, std::vector<std::string>> aliases;  // from -> to, no pair twice
  std::vector<ImportAlias> alias_list;                       // the same, with where each came from
  // The files each file imports: a body in a file sees the names of the
  // file and of these, transitively (under their prefixes), nothing else.
  std::map<const SourceFile*, std::vector<const SourceFile*>> edges;
};

// Imports are nested at most this deep (a chain, not a cycle, of files).
constexpr int kMaxImportDepth = 50;

ImportSet loadImports(const ast::File& file, const SourceFile& source, Diagnostics& diags);

// The key `key` ("y.b.post") is bound under, following `aliases` ("x.b.post"):
// the first that `bound` accepts, the longest alias first; "" when none.
// `inside`: the length of the namespace the key is looked up in (a body of a
// file bound as "x." looks up "x.name"; 0 in the checked file). Each
// (key, namespace) is tried once.
std::string resolveImportedKey(const std::map<std::string, std::vector<std::string>>& aliases,
                               const std::string& key, size_t inside,
                               const std::function<bool(const std::string&)>& bound);

}  // namespace sdfc
