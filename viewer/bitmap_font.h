// A 5x7 bitmap font of our own (ASCII 32-126) for text drawn into the
// viewer's RGB8 image on the CPU: the error overlay (error_overlay.h).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace sdfc::view {

constexpr int kGlyphColumns = 5, kGlyphRows = 7;
constexpr int kGlyphAdvance = 6;     // columns per character, a blank one included
constexpr int kGlyphLineHeight = 9;  // rows per line of text, two blank ones included

// The glyph's rows (top first, bit 4 the leftmost column); '?' for a
// character outside ASCII 32-126.
const uint8_t* glyphRows(char c);

// Draws `text` with its top-left corner at (x, y), each font pixel a
// scale x scale square; what falls outside the image is clipped.
void drawText(std::vector<uint8_t>& rgb, uint32_t width, uint32_t height, int x, int y,
              const std::string& text, int scale, const uint8_t colour[3]);

}  // namespace sdfc::view
