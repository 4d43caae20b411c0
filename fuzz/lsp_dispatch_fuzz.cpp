// libFuzzer target: the language server's handling of messages (lsp/server.cpp
// and every feature behind it), not only its framing. One input is a list of
// JSON-RPC message bodies, one per line; the server gets `initialize`, the
// opening of a small scene, each line as a framed message, then `shutdown` and
// `exit`, on an in-memory stream, and answers on another. Every reply must be
// a whole frame of JSON, and the server must end (no crash, hang or leak).
#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>

#include "fuzz/dispatch_input.h"
#include "lsp/server.h"
#include "lsp/transport.h"

namespace {

[[noreturn]] void broken(const std::string& why) {
  std::fprintf(stderr, "sdfc_lsp_dispatch_fuzz: %s\n", why.c_str());
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string in =
      sdfc::fuzz::dispatchStream(std::string(reinterpret_cast<const char*>(data), size));
  std::istringstream input(in);
  std::ostringstream output;
  (void)sdfc::lsp::runServer(input, output);
  // What the server wrote: whole frames, each body one JSON value.
  std::istringstream replies(output.str());
  while (std::optional<sdfc::lsp::Frame> f = sdfc::lsp::readFrame(replies)) {
    if (f->malformed || f->too_large) broken("a reply that is not a whole frame");
    if (!nlohmann::json::accept(f->body)) broken("a reply that is not JSON: " + f->body.substr(0, 200));
  }
  return 0;
}
