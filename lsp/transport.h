// JSON-RPC 2.0 framing over a byte stream, as LSP specifies: a
// `Content-Length: N` header, a blank line, then N bytes of JSON.
#pragma once
#include <istream>
#include <mutex>
#include <optional>
#include <ostream>
#include <string>

namespace sdfc::lsp {

// A body larger than this is refused (and skipped) rather than allocated.
inline constexpr size_t kMaxBodyBytes = size_t(64) << 20;

struct Frame {
  std::string body;
  bool malformed = false;  // headers without a usable Content-Length (body is empty)
  bool too_large = false;  // a body over the limit, skipped (body is empty)
};

// The next frame, or nullopt at end of input.
std::optional<Frame> readFrame(std::istream& in);

// Writes whole frames; safe to call from any thread.
class Writer {
 public:
  explicit Writer(std::ostream& out) : out_(&out) {}
  // Straight to a file descriptor with write(2): no stream buffer in between.
  explicit Writer(int fd) : fd_(fd) {}
  void send(const std::string& body);

 private:
  std::ostream* out_ = nullptr;
  int fd_ = -1;
  std::mutex mutex_;
};

}  // namespace sdfc::lsp
