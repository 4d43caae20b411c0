// One version of one document, compiled once and shared by every request on
// it: the checker's diagnostics (exactly `sdfc check`'s), the syntax tree with
// its comments and tokens, the analysed IR (exactness per node) and an index
// of every `let` name's definition and uses.
#pragma once
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "driver/compile.h"
#include "lsp/catalogue.h"
#include "lsp/documents.h"
#include "syntax/ast.h"
#include "syntax/token.h"

namespace sdfc::lsp {

struct NameUse {
  std::string name;
  SourceRange range;
  bool definition = false;
  // A parameter: the parametric `let` it belongs to (its uses in the body,
  // and named arguments at calls); null for a `let` name.
  const ast::Statement* scope = nullptr;
};

struct Analysis {
  std::string uri;
  int version = 0;
  CompiledScene compiled;  // owns the SourceFile every range points into
  Diagnostics diagnostics;
  ast::File tree;
  std::vector<Token> tokens;
  std::vector<Comment> comments;
  LineIndex lines;
  std::map<std::string, const ast::Statement*> lets;  // first definition of each name
  std::vector<NameUse> uses;                           // definitions and uses, in source order
  std::map<size_t, const ir::Node*> nodes;             // IR node by its call's start offset
  std::map<std::string, CalleeDoc> definitions;        // parametric `let`s, documented as callees
  // Definitions brought in by `import`, by the name this file uses for them
  // ("tower", "parts.tower"): where each is defined in its own file.
  // Each imported file's definitions are listed once, under the prefix it was
  // first reached by; another name for it goes through these (check/imports.h).
  std::map<std::string, SourceRange> imported;
  std::map<std::string, std::vector<std::string>> import_aliases;
  // What hover shows for an imported definition, by the same key as
  // `imported`: its text, and for a parametric one its signature.
  struct ImportedDoc {
    std::string text;
    std::string file;  // the file it is defined in, as the import named it
    bool parametric = false;
    CalleeDoc callee;
  };
  std::map<std::string, ImportedDoc> imported_docs;
  bool utf8 = false;

  const std::string& text() const { return compiled.source->text; }
  const SourceFile& source() const { return *compiled.source; }
  // The use or definition of a `let` name under `offset` (or just before it).
  const NameUse* nameAt(size_t offset) const;
  // A built-in or a parametric definition of this file.
  const CalleeDoc* callee(const std::string& name) const;
  // The parametric `let` whose text holds `offset`, if any.
  const ast::Statement* enclosingDefinition(size_t offset) const;
  // An LSP location for a range in this document or in an imported file.
  json location(const SourceRange& r) const;
  // Where the imported definition this file calls `name` is defined, or null.
  const SourceRange* importedAt(const std::string& name) const;
  // The key `imported` holds the definition this file calls `name` under
  // (through aliases), or "" when it is not imported.
  std::string importedKey(const std::string& name) const;
  // The IR node a `let` shape compiles to, if any.
  const ir::Node* definitionNode(const std::string& name) const;
};

std::shared_ptr<const Analysis> analyzeDocument(const Document& doc, bool utf8);

// file:///a/b%20c.sdf <-> /a/b c.sdf (other URIs are kept as they are).
std::string uriToPath(const std::string& uri);
std::string pathToUri(const std::string& path);

}  // namespace sdfc::lsp
