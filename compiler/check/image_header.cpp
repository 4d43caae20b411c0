#include "check/image_header.h"

#include <tinyexr.h>

#include <cctype>
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

}  // namespace sdfc
