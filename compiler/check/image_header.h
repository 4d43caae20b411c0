// What texture(file:) and sky(map:) both need before decoding an image: its
// extension, and an EXR's size from its header (so a huge image is refused
// undecoded).
#pragma once
#include <string>

namespace sdfc {

std::string lowerExtension(const std::string& path);

// The EXR at `path`'s data window size; "" on success, else why it cannot be read.
std::string exrSizeFromHeader(const std::string& path, int& width, int& height);

}  // namespace sdfc
