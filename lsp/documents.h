// The open documents: text and version per URI, edited by incremental
// changes, and the conversion between LSP positions (line, UTF-16 or UTF-8
// code unit) and byte offsets.
#pragma once
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace sdfc::lsp {

using json = nlohmann::json;

// Line starts of one text, for position <-> offset conversion.
class LineIndex {
 public:
  LineIndex() = default;
  LineIndex(const std::string& text, bool utf8);
  size_t offsetOf(const json& position) const;  // clamped into the text
  json positionOf(size_t offset) const;
  json rangeOf(size_t begin, size_t end) const;

 private:
  const std::string* text_ = nullptr;
  std::vector<size_t> starts_;
  bool utf8_ = false;
};

// The largest document the server analyses. An analysis holds about 270
// bytes per byte of text (tokens, syntax trees, the IR, the index): a
// 28 MB document took 7.7 GB and then aborted. A larger document is kept (so
// its edits still apply) but not analysed: its diagnostics are one error
// saying so, and requests on it fail with RequestFailed.
inline constexpr size_t kMaxDocumentBytes = size_t(4) << 20;
std::string documentTooLarge(size_t bytes);  // "" when `bytes` may be analysed

struct Document {
  std::string uri;
  int version = 0;
  std::string text;
};

class DocumentStore {
 public:
  void open(const std::string& uri, int version, std::string text);
  // Applies textDocument/didChange's contentChanges in order; false if the
  // document is not open.
  bool change(const std::string& uri, int version, const json& changes, bool utf8);
  void close(const std::string& uri);
  // A copy of the document, so a worker never sees it change under it.
  std::shared_ptr<const Document> get(const std::string& uri) const;

 private:
  mutable std::mutex mutex_;
  std::map<std::string, std::shared_ptr<const Document>> docs_;
};

}  // namespace sdfc::lsp
