// libFuzzer target: the language server's JSON-RPC framing (lsp/transport.cpp)
// and the JSON parse of each body, on an arbitrary byte stream: frames must
// come out until the end of input, each within the body limit.
#include <nlohmann/json.hpp>

#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "lsp/transport.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  size_t frames = 0;
  while (std::optional<sdfc::lsp::Frame> frame = sdfc::lsp::readFrame(in)) {
    if (frame->body.size() > sdfc::lsp::kMaxBodyBytes || ++frames > size + 1) {
      std::fprintf(stderr, "lsp_frame_fuzz: a body over the limit, or frames from nothing\n");
      std::abort();
    }
    (void)nlohmann::json::parse(frame->body, nullptr, false);
  }
  return 0;
}
