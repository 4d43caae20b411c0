// The language features, one file per group, each a pure function of one
// document's Analysis (so any number run at once on worker threads).
#pragma once
#include <stdexcept>
#include <string>

#include "lsp/analysis.h"

namespace sdfc::lsp {

// JSON-RPC error codes (LSP 3.17).
constexpr int kParseError = -32700;
constexpr int kInvalidRequest = -32600;
constexpr int kMethodNotFound = -32601;
constexpr int kInvalidParams = -32602;
constexpr int kInternalError = -32603;
constexpr int kServerNotInitialized = -32002;
constexpr int kRequestFailed = -32803;
constexpr int kRequestCancelled = -32800;

struct RpcError : std::runtime_error {
  int code;
  RpcError(int code_, const std::string& message) : std::runtime_error(message), code(code_) {}
};

// diagnostics.cpp: textDocument/publishDiagnostics params.
json publishDiagnostics(const Analysis& a);
// hover.cpp
json hover(const Analysis& a, size_t offset);
// navigation.cpp: definition, references, rename.
json definition(const Analysis& a, size_t offset);
json references(const Analysis& a, size_t offset, bool include_declaration);
json prepareRename(const Analysis& a, size_t offset);
json rename(const Analysis& a, size_t offset, const std::string& new_name);
json documentHighlight(const Analysis& a, size_t offset);
// completion.cpp: completion and signature help.
json completion(const Analysis& a, size_t offset);
json signatureHelp(const Analysis& a, size_t offset);
// symbols.cpp
json documentSymbols(const Analysis& a);
// formatting.cpp
json formatting(const Analysis& a);

}  // namespace sdfc::lsp
