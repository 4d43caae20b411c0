#include "check/image_header.h"

#include <tinyexr.h>

#include <cctype>
#include <cstdlib>
#include <filesystem>

namespace sdfc {

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

std::string exrSizeFromHeader(const std::string& path, int& width, int& height) {
  EXRVersion version;
  if (ParseEXRVersionFromFile(&version, path.c_str()) != TINYEXR_SUCCESS) return "it is not an EXR file";
  EXRHeader header;
  InitEXRHeader(&header);
  const char* err = nullptr;
  if (ParseEXRHeaderFromFile(&header, &version, path.c_str(), &err) != TINYEXR_SUCCESS) {
    std::string reason = err ? err : "its EXR header cannot be read";
    FreeEXRErrorMessage(err);
    return reason;
  }
  width = header.data_window.max_x - header.data_window.min_x + 1;
  height = header.data_window.max_y - header.data_window.min_y + 1;
  FreeEXRHeader(&header);
  return "";
}

std::string decodeExrRgb(const std::string& path, ir::TextureImage& image) {
  const char* err = nullptr;
  float* rgba = nullptr;
  int width = 0, height = 0;
  if (LoadEXR(&rgba, &width, &height, path.c_str(), &err) != TINYEXR_SUCCESS) {
    std::string reason = err ? err : "it cannot be decoded";
    FreeEXRErrorMessage(err);
    return reason;
  }
  image.width = width;
  image.height = height;
  image.rgb.resize(size_t(width) * height * 3);
  for (size_t i = 0; i < size_t(width) * height; ++i)
    for (int c = 0; c < 3; ++c) image.rgb[i * 3 + c] = rgba[i * 4 + c];
  std::free(rgba);
  return "";
}

}  // namespace sdfc
