// The language server: reads JSON-RPC messages, keeps the open documents,
// answers requests on a pool of worker threads that grows while all are busy
// (so a request never waits behind another, up to 8 at once) and publishes
// diagnostics from a background thread after edits.
#pragma once
#include <istream>
#include <ostream>

namespace sdfc::lsp {

// Serves until `exit` or end of input; returns the process exit code
// (0 after a `shutdown` request, 1 otherwise, as the protocol asks).
int runServer(std::istream& in, std::ostream& out);
int runServer(std::istream& in, int out_fd);
int runStdioServer();

}  // namespace sdfc::lsp
