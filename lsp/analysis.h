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
#include "lsp/documents.h"
#include "syntax/ast.h"
#include "syntax/token.h"

namespace sdfc::lsp {

struct NameUse {
  std::string name;
  SourceRange range;
  bool definition = false;
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

  const std::string& text() const { return compiled.source->text; }
  const SourceFile& source() const { return *compiled.source; }
  // The use or definition of a `let` name under `offset` (or just before it).
  const NameUse* nameAt(size_t offset) const;
  // The IR node a `let` shape compiles to, if any.
  const ir::Node* definitionNode(const std::string& name) const;
};

std::shared_ptr<const Analysis> analyzeDocument(const Document& doc, bool utf8);

}  // namespace sdfc::lsp
