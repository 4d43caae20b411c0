#include "lsp/documents.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

namespace sdfc::lsp {

LineIndex::LineIndex(const std::string& text, bool utf8) : text_(&text), utf8_(utf8) {
  starts_.push_back(0);
  for (size_t i = 0; i < text.size(); ++i)
    if (text[i] == '\n') starts_.push_back(i + 1);
}

namespace {
// Bytes in the UTF-8 sequence starting with `c` (1 for stray continuation bytes).
size_t sequenceLength(unsigned char c) {
  if (c >= 0xF0) return 4;
  if (c >= 0xE0) return 3;
  if (c >= 0xC0) return 2;
  return 1;
}
}  // namespace

size_t LineIndex::offsetOf(const json& position) const {
  if (!position.is_object() || !position.contains("line") || !position.contains("character") ||
      !position["line"].is_number_integer() || !position["character"].is_number_integer())
    throw std::invalid_argument("a position needs integer 'line' and 'character'");
  const long long line = position["line"].get<long long>();
  long long units = position["character"].get<long long>();
  if (line < 0 || units < 0) throw std::invalid_argument("a position cannot be negative");
  if (static_cast<size_t>(line) >= starts_.size()) return text_->size();
  size_t i = starts_[static_cast<size_t>(line)];
  while (units > 0 && i < text_->size() && (*text_)[i] != '\n') {
    const size_t n = std::min(sequenceLength(static_cast<unsigned char>((*text_)[i])), text_->size() - i);
    units -= utf8_ ? static_cast<long long>(n) : (n == 4 ? 2 : 1);
    i += n;
  }
  return i;
}

json LineIndex::positionOf(size_t offset) const {
  offset = std::min(offset, text_->size());
  const size_t line = static_cast<size_t>(std::upper_bound(starts_.begin(), starts_.end(), offset) -
                                          starts_.begin()) - 1;
  size_t units = 0;
  for (size_t i = starts_[line]; i < offset;) {
    const size_t n = sequenceLength(static_cast<unsigned char>((*text_)[i]));
    units += utf8_ ? n : (n == 4 ? 2 : 1);
    i += n;
  }
  return {{"line", line}, {"character", units}};
}

json LineIndex::rangeOf(size_t begin, size_t end) const {
  return {{"start", positionOf(begin)}, {"end", positionOf(end)}};
}

std::string documentTooLarge(size_t bytes) {
  if (bytes <= kMaxDocumentBytes) return "";
  const auto mib = [](size_t n) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f MiB", double(n) / double(1 << 20));
    return std::string(text);
  };
  return "this document is " + mib(bytes) + "; the language server analyses documents up to " +
         mib(kMaxDocumentBytes) + " (run `sdfc check` on the file, which reads up to 256 MiB)";
}

void DocumentStore::open(const std::string& uri, int version, std::string text) {
  auto doc = std::make_shared<Document>(Document{uri, version, std::move(text)});
  std::lock_guard<std::mutex> lock(mutex_);
  docs_[uri] = std::move(doc);
}

bool DocumentStore::change(const std::string& uri, int version, const json& changes, bool utf8) {
  std::shared_ptr<const Document> old = get(uri);
  if (!old) return false;
  if (!changes.is_array()) throw std::invalid_argument("contentChanges must be an array");
  std::string text = old->text;
  for (const json& c : changes) {
    if (!c.is_object() || !c.contains("text") || !c["text"].is_string())
      throw std::invalid_argument("a content change needs 'text'");
    if (c.contains("range")) {
      const LineIndex lines(text, utf8);
      size_t begin = lines.offsetOf(c["range"].at("start"));
      size_t end = lines.offsetOf(c["range"].at("end"));
      if (end < begin) std::swap(begin, end);
      text.replace(begin, end - begin, c["text"].get<std::string>());
    } else {
      text = c["text"].get<std::string>();
    }
  }
  auto doc = std::make_shared<Document>(Document{uri, version, std::move(text)});
  std::lock_guard<std::mutex> lock(mutex_);
  docs_[uri] = std::move(doc);
  return true;
}

void DocumentStore::close(const std::string& uri) {
  std::lock_guard<std::mutex> lock(mutex_);
  docs_.erase(uri);
}

std::shared_ptr<const Document> DocumentStore::get(const std::string& uri) const {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = docs_.find(uri);
  return it == docs_.end() ? nullptr : it->second;
}

}  // namespace sdfc::lsp
