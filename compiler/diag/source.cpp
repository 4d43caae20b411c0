#include "diag/source.h"

#include <algorithm>
#include <cerrno>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace sdfc {

SourceFile::SourceFile(std::string path_, std::string text_)
    : path(std::move(path_)), text(std::move(text_)) {
  // Lines end at "\n", "\r\n" or a lone "\r" (old Mac files).
  line_starts.push_back(0);
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '\n' || (text[i] == '\r' && (i + 1 == text.size() || text[i + 1] != '\n')))
      line_starts.push_back(i + 1);
  }
}

size_t codePointCount(std::string_view bytes) {
  size_t n = 0;
  for (char c : bytes) n += (static_cast<unsigned char>(c) & 0xC0) != 0x80;  // not a continuation byte
  return n;
}

size_t SourceFile::lineStart(int line) const {
  if (line < 1 || static_cast<size_t>(line) > line_starts.size()) return text.size();
  return line_starts[line - 1];
}

std::pair<int, int> SourceFile::lineColumn(size_t offset) const {
  offset = std::min(offset, text.size());
  auto it = std::upper_bound(line_starts.begin(), line_starts.end(), offset);
  const size_t line = static_cast<size_t>(it - line_starts.begin());  // 1-based
  const size_t begin = line_starts[line - 1];
  const size_t column = codePointCount(std::string_view(text).substr(begin, offset - begin)) + 1;
  return {static_cast<int>(line), static_cast<int>(column)};
}

std::string_view SourceFile::lineText(int line) const {
  if (line < 1 || static_cast<size_t>(line) > line_starts.size()) return {};
  const size_t begin = line_starts[line - 1];
  size_t end = text.find_first_of("\r\n", begin);
  if (end == std::string::npos) end = text.size();
  return std::string_view(text).substr(begin, end - begin);
}

std::string sourceFileProblem(const std::string& path) {
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(path, error);
  if (error) return "";  // missing or unreadable: the open says why (errno)
  if (std::filesystem::is_directory(status)) return "it is a directory, not a scene file";
  if (!std::filesystem::is_regular_file(status)) return "it is not a regular file (a FIFO, device or socket)";
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (!error && size > kMaxSourceBytes)
    return "it is " + std::to_string(size >> 20) + " MiB, more than a scene file's " +
           std::to_string(kMaxSourceBytes >> 20) + " MiB";
  return "";
}

std::unique_ptr<SourceFile> readSourceFile(const std::string& path) {
  // A directory opens as a stream on Linux and reads as empty, a FIFO blocks.
  if (!sourceFileProblem(path).empty()) {
    std::error_code error;
    errno = std::filesystem::is_directory(path, error) ? EISDIR : EINVAL;
    return nullptr;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return nullptr;
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) return nullptr;
  std::string text = buffer.str();
  // Editors on Windows may start a UTF-8 file with a byte order mark.
  if (text.rfind("\xEF\xBB\xBF", 0) == 0) text.erase(0, 3);
  return std::make_unique<SourceFile>(path, std::move(text));
}

}  // namespace sdfc
