#include "error_overlay.h"

#include <algorithm>
#include <filesystem>

#include "bitmap_font.h"
#include "diag/diagnostics.h"

namespace sdfc::view {

std::string firstErrorText(const Diagnostics& diagnostics) {
  const Diagnostic* first = nullptr;
  for (const Diagnostic& d : diagnostics.all()) {
    if (d.severity != Severity::Error) continue;
    // The order the terminal prints them in (Diagnostics::format): by offset, the first reported on a tie.
    if (!first || d.range.begin < first->range.begin) first = &d;
  }
  if (!first) return "";
  if (!first->range.file) return first->message;
  const auto [line, col] = first->range.file->lineColumn(first->range.begin);
  return std::filesystem::path(first->range.file->path).filename().string() + ":" + std::to_string(line) + ":" +
         std::to_string(col) + ": " + first->message;
}

namespace {

// `text` in lines of at most `columns` characters, broken at spaces where it can.
std::vector<std::string> wrap(const std::string& text, size_t columns) {
  std::vector<std::string> lines;
  size_t at = 0;
  while (at < text.size()) {
    size_t end = std::min(text.size(), at + columns);
    if (end < text.size()) {
      const size_t space = text.rfind(' ', end);
      if (space != std::string::npos && space > at) end = space;
    }
    lines.push_back(text.substr(at, end - at));
    at = end;
    while (at < text.size() && text[at] == ' ') ++at;
  }
  return lines;
}

}  // namespace

uint32_t drawErrorOverlay(std::vector<uint8_t>& rgb, uint32_t width, uint32_t height, const std::string& text) {
  if (text.empty() || width < 16 || height < 16) return height;
  // Font pixels of 1, 2 or 3 image pixels: readable from a small window to a large one.
  const int scale = std::clamp(int(width) / 480 + 1, 1, 3);
  const int margin = 2 * scale;
  const size_t columns = std::max<size_t>(1, (width - 2 * margin) / (kGlyphAdvance * scale));
  std::vector<std::string> lines = wrap("ERROR " + text, columns);
  if (lines.size() > size_t(kOverlayMaxLines)) {
    lines.resize(kOverlayMaxLines);
    std::string& last = lines.back();
    last = last.substr(0, std::min(last.size(), columns - std::min<size_t>(columns, 3))) + "...";
  }
  const int banner = int(lines.size()) * kGlyphLineHeight * scale + 2 * margin;
  const uint32_t top = uint32_t(std::max(0, int(height) - banner));
  // The image darkened under the banner, so the text reads on any scene.
  for (uint32_t y = top; y < height; ++y) {
    uint8_t* row = rgb.data() + size_t(y) * width * 3;
    for (uint32_t x = 0; x < width; ++x) {
      row[3 * x] = uint8_t(64 + row[3 * x] / 8);
      row[3 * x + 1] = uint8_t(row[3 * x + 1] / 8);
      row[3 * x + 2] = uint8_t(row[3 * x + 2] / 8);
    }
  }
  const uint8_t white[3] = {255, 255, 255};
  for (size_t i = 0; i < lines.size(); ++i)
    drawText(rgb, width, height, margin, int(top) + margin + int(i) * kGlyphLineHeight * scale, lines[i], scale,
             white);
  return top;
}

}  // namespace sdfc::view
