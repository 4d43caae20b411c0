// `sdfc lsp`: the language server (lsp/) on stdin and stdout.
#include "commands.h"
#include "lsp/server.h"

namespace sdfc {

int runLsp(const CommandLine&) { return lsp::runStdioServer(); }

}  // namespace sdfc
