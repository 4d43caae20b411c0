// What texture(file:) and sky(map:) both need to read an image: its
// extension, an EXR's size from its header (so a huge image is refused
// undecoded), and an EXR's RGB decoded.
#pragma once
#include <string>

#include "ir/scene.h"

namespace sdfc {

std::string lowerExtension(const std::string& path);

// The EXR at `path`'s data window size; "" on success, else why it cannot be read.
std::string exrSizeFromHeader(const std::string& path, int& width, int& height);

// The EXR's RGB as stored (alpha dropped) into `image`'s size and texels; "" on
// success, else why it cannot be decoded.
std::string decodeExrRgb(const std::string& path, ir::TextureImage& image);

}  // namespace sdfc
