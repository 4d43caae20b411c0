#include "check/image_header.h"

#include <stb_image.h>
#include <tinyexr.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace sdfc {

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

namespace {

// The header's line order and tiling: "" on success.
std::string readExrHeader(const std::string& path, EXRHeader& header) {
  EXRVersion version;
  if (ParseEXRVersionFromFile(&version, path.c_str()) != TINYEXR_SUCCESS) return "it is not an EXR file";
  InitEXRHeader(&header);
  const char* err = nullptr;
  if (ParseEXRHeaderFromFile(&header, &version, path.c_str(), &err) != TINYEXR_SUCCESS) {
    std::string reason = err ? err : "its EXR header cannot be read";
    FreeEXRErrorMessage(err);
    // What tinyexr read before it failed (channels, attributes) is still held.
    FreeEXRHeader(&header);
    return reason;
  }
  return "";
}

}  // namespace

std::string exrSizeFromHeader(const std::string& path, int& width, int& height) {
  EXRHeader header;
  if (std::string why = readExrHeader(path, header); !why.empty()) return why;
  // In 64 bits: a window from -2^31 to 2^31 - 1 is 2^32 wide.
  const long long w = (long long)header.data_window.max_x - header.data_window.min_x + 1,
                  h = (long long)header.data_window.max_y - header.data_window.min_y + 1;
  FreeEXRHeader(&header);
  if (w <= 0 || h <= 0 || w > (1 << 30) || h > (1 << 30))
    return "its data window is " + std::to_string(w) + " x " + std::to_string(h) + " texels";
  width = int(w);
  height = int(h);
  return "";
}

std::string decodeExrRgba(const std::string& path, std::vector<float>& out, int& width, int& height) {
  EXRHeader header;
  if (std::string why = readExrHeader(path, header); !why.empty()) return why;
  const bool bottom_first = header.line_order == 1, tiled = header.tiled != 0;
  FreeEXRHeader(&header);
  // tinyexr flips each tile by the tile's nominal height, which no later flip
  // undoes for a partial tile: refused rather than read wrong.
  if (bottom_first && tiled)
    return "it is tiled and stored bottom first (lineOrder DECREASING_Y), which sdfc does not read; "
           "write it as scan lines or top first";
  const char* err = nullptr;
  float* rgba = nullptr;
  if (LoadEXR(&rgba, &width, &height, path.c_str(), &err) != TINYEXR_SUCCESS) {
    std::string reason = err ? err : "it cannot be decoded";
    FreeEXRErrorMessage(err);
    return reason;
  }
  const size_t row = size_t(width) * 4;
  out.resize(row * size_t(height));
  for (int y = 0; y < height; ++y)
    std::memcpy(&out[row * size_t(y)], rgba + row * size_t(bottom_first ? height - 1 - y : y), row * sizeof(float));
  std::free(rgba);
  return "";
}

std::string decodeExrRgb(const std::string& path, ir::TextureImage& image) {
  std::vector<float> rgba;
  int width = 0, height = 0;
  if (std::string why = decodeExrRgba(path, rgba, width, height); !why.empty()) return why;
  image.width = width;
  image.height = height;
  image.rgb.resize(size_t(width) * height * 3);
  for (size_t i = 0; i < size_t(width) * height; ++i)
    for (int c = 0; c < 3; ++c) image.rgb[i * 3 + c] = rgba[i * 4 + c];
  return "";
}

// The format as stb_image 2.x reads it: text lines up to an empty one, the
// resolution line "-Y h +X w", then h scan lines. At a width from 8 to 32767
// a line that starts 2 2 hi lo is run-length encoded, each of its four
// components in runs (a count above 128: one byte repeated count - 128 times;
// otherwise count literal bytes); at any other width, or from the first line
// that does not start so, stb reads w * h flat 4-byte texels from there.
std::string hdrTruncation(const std::vector<unsigned char>& bytes) {
  size_t at = 0;
  auto line = [&]() -> std::string {
    std::string s;
    while (at < bytes.size() && bytes[at] != '\n') s += char(bytes[at++]);
    if (at < bytes.size()) ++at;
    return s;
  };
  while (at < bytes.size() && !line().empty()) {
  }
  int w = 0, h = 0;
  if (std::sscanf(line().c_str(), "-Y %d +X %d", &h, &w) != 2 || w <= 0 || h <= 0)
    return "its resolution line is not '-Y height +X width'";
  const size_t n = bytes.size();
  auto missing = [&](size_t y) {
    return "it ends after " + std::to_string(y) + " of its " + std::to_string(h) +
           " rows (a truncated file: stb_image would repeat one texel for the rest)";
  };
  for (int y = 0; y < h; ++y) {
    const bool rle = w >= 8 && w < 32768 && at + 4 <= n && bytes[at] == 2 && bytes[at + 1] == 2 &&
                     !(bytes[at + 2] & 128);
    if (!rle) {
      const size_t have = n - std::min(at, n), row = size_t(w) * 4;
      return have < row * size_t(h) ? missing(std::min(size_t(y) + have / row, size_t(h) - 1)) : "";
    }
    at += 4;
    for (int k = 0; k < 4; ++k)
      for (int i = 0; i < w;) {
        if (at >= n) return missing(y);
        int count = bytes[at++];
        if (count > 128) {
          count -= 128;
          if (at >= n) return missing(y);
          ++at;
        } else {
          if (n - at < size_t(count)) return missing(y);
          at += size_t(count);
        }
        // A run of 0 would hang stb_image's loop.
        if (count == 0 || count > w - i) return "its row " + std::to_string(y) + " has bad run-length data";
        i += count;
      }
  }
  return "";
}

std::string decodeHdrRgb(const std::string& path, ir::TextureImage& image) {
  // The largest map, 4096 x 2048 flat texels, is 32 MiB and run-length
  // encoding only shortens it: a larger file is not read whole.
  constexpr uintmax_t kMaxBytes = uintmax_t(64) << 20;
  std::error_code ec;
  if (std::filesystem::file_size(path, ec) > kMaxBytes || ec)
    return ec ? "it cannot be read" : "it is over 64 MiB, more than the largest map or texture takes";
  std::ifstream file(path, std::ios::binary);
  const std::vector<unsigned char> bytes{std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
  if (!file.good() && !file.eof()) return "it cannot be read";
  if (std::string why = hdrTruncation(bytes); !why.empty()) return why;
  int w = 0, h = 0, channels = 0;
  float* data = stbi_loadf_from_memory(bytes.data(), int(bytes.size()), &w, &h, &channels, 3);
  if (!data) return std::string("it cannot be decoded (") + stbi_failure_reason() + ")";
  image.width = w;
  image.height = h;
  image.rgb.assign(data, data + size_t(w) * h * 3);
  stbi_image_free(data);
  return "";
}

}  // namespace sdfc
