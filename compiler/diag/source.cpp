#include "diag/source.h"

#include <algorithm>
#include <fstream>
#include <sstream>

namespace sdfc {

SourceFile::SourceFile(std::string path_, std::string text_)
    : path(std::move(path_)), text(std::move(text_)) {
  line_starts.push_back(0);
  for (size_t i = 0; i < text.size(); ++i)
    if (text[i] == '\n') line_starts.push_back(i + 1);
}

std::pair<int, int> SourceFile::lineColumn(size_t offset) const {
  auto it = std::upper_bound(line_starts.begin(), line_starts.end(), offset);
  const size_t line = static_cast<size_t>(it - line_starts.begin());  // 1-based
  return {static_cast<int>(line), static_cast<int>(offset - line_starts[line - 1] + 1)};
}

std::string_view SourceFile::lineText(int line) const {
  if (line < 1 || static_cast<size_t>(line) > line_starts.size()) return {};
  const size_t begin = line_starts[line - 1];
  size_t end = text.find('\n', begin);
  if (end == std::string::npos) end = text.size();
  if (end > begin && text[end - 1] == '\r') --end;
  return std::string_view(text).substr(begin, end - begin);
}

std::unique_ptr<SourceFile> readSourceFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return nullptr;
  std::ostringstream buffer;
  buffer << in.rdbuf();
  return std::make_unique<SourceFile>(path, buffer.str());
}

}  // namespace sdfc
