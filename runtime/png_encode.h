// PNG encoding for `sdfc render` (image_io.cpp): 8-bit RGB, zlib at its fastest
// level with the Sub filter on every row. stb's writer (level 8, five filters
// tried per row) took 39 ms for a 640x360 render and wrote a larger file; this
// takes 6.5 ms and writes 24% less (bench/results/fixed_costs.md). An image of
// 256 KiB or more is deflated in two halves on two threads, joined into one
// zlib stream (bench/results/PNG_ENCODE.md).
#pragma once
#include <cstdint>
#include <string>

namespace sdfc {

// A whole PNG file: `rgb` is width * height * 3 bytes, rows top first.
// Throws std::runtime_error when zlib fails (out of memory).
std::string encodePng(const uint8_t* rgb, uint32_t width, uint32_t height);

}  // namespace sdfc
