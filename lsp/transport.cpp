#include "lsp/transport.h"

#include <cctype>
#include <cerrno>
#include <unistd.h>

namespace sdfc::lsp {

std::optional<Frame> readFrame(std::istream& in) {
  Frame frame;
  long long length = -1;
  bool any_header = false;
  std::string line;
  while (true) {
    if (!std::getline(in, line)) return std::nullopt;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) {
      if (!any_header) continue;  // stray blank lines between frames
      break;
    }
    any_header = true;
    const size_t colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::string key = line.substr(0, colon);
    for (char& c : key) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (key == "content-length") {
      try {
        size_t used = 0;
        const std::string value = line.substr(colon + 1);
        length = std::stoll(value, &used);
        for (size_t i = used; i < value.size(); ++i)
          if (!std::isspace(static_cast<unsigned char>(value[i]))) length = -1;
      } catch (const std::exception&) {
        length = -1;
      }
    }
  }
  if (length < 0) {
    frame.malformed = true;
    return frame;
  }
  if (static_cast<unsigned long long>(length) > kMaxBodyBytes) {
    // Read past the body unallocated, so the next frame starts where it should.
    in.ignore(static_cast<std::streamsize>(length));
    if (in.gcount() != length) return std::nullopt;
    frame.too_large = true;
    return frame;
  }
  frame.body.resize(static_cast<size_t>(length));
  in.read(frame.body.data(), length);
  if (in.gcount() != length) return std::nullopt;
  return frame;
}

void Writer::send(const std::string& body) {
  const std::string frame = "Content-Length: " + std::to_string(body.size()) + "\r\n\r\n" + body;
  std::lock_guard<std::mutex> lock(mutex_);
  if (out_) {
    out_->write(frame.data(), static_cast<std::streamsize>(frame.size()));
    out_->flush();
    return;
  }
  for (size_t done = 0; done < frame.size();) {
    const ssize_t n = ::write(fd_, frame.data() + done, frame.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;  // the client has gone; the read loop ends at end of input
    done += static_cast<size_t>(n);
  }
}

}  // namespace sdfc::lsp
