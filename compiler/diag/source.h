// A source file held in memory, and positions inside it.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace sdfc {

struct SourceFile {
  std::string path;
  std::string text;
  std::vector<size_t> line_starts;  // byte offset of each line's first character

  SourceFile(std::string path_, std::string text_);
  // 1-based line and column of a byte offset. Columns count characters
  // (UTF-8 code points), so a caret lines up after "è"; lines end at \n,
  // \r\n or a lone \r.
  std::pair<int, int> lineColumn(size_t offset) const;
  std::string_view lineText(int line) const;  // without the line ending
  size_t lineStart(int line) const;           // byte offset of the line's first character
};

// Characters (UTF-8 code points; a stray byte counts as one) in `bytes`.
size_t codePointCount(std::string_view bytes);

// A half-open byte range [begin, end) in one file.
struct SourceRange {
  const SourceFile* file = nullptr;
  size_t begin = 0;
  size_t end = 0;
  int line() const { return file ? file->lineColumn(begin).first : 0; }
  SourceRange to(const SourceRange& other) const { return {file, begin, other.end}; }
};

// Why `path` is no scene file to read ("" when it may be read): a directory,
// anything but a regular file (a FIFO would block, /dev/zero never end), or
// a file beyond kMaxSourceBytes.
constexpr std::uintmax_t kMaxSourceBytes = std::uintmax_t(256) << 20;
std::string sourceFileProblem(const std::string& path);
// Reads a file, less a leading UTF-8 byte order mark; nullptr when it cannot
// be read (errno says why, or sourceFileProblem does).
std::unique_ptr<SourceFile> readSourceFile(const std::string& path);

}  // namespace sdfc
