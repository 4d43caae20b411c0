// What texture(file:) and sky(map:) both need to read an image: its
// extension, an EXR's size from its header (so a huge image is refused
// undecoded), an EXR's pixels decoded, and a Radiance .hdr file's rows
// checked to be all there.
#pragma once
#include <string>
#include <vector>

#include "ir/scene.h"

namespace sdfc {

std::string lowerExtension(const std::string& path);

// The EXR at `path`'s data window size; "" on success, else why it cannot be read.
std::string exrSizeFromHeader(const std::string& path, int& width, int& height);

// The EXR's RGBA as stored, rows top first whatever the file's line order
// (tinyexr 1.0 places a DECREASING_Y file's rows upside down: its chunks carry
// their own y, the order is only the order they are stored in); "" on
// success, else why it cannot be decoded.
std::string decodeExrRgba(const std::string& path, std::vector<float>& rgba, int& width, int& height);

// The EXR's RGB as stored (alpha dropped) into `image`'s size and texels; "" on
// success, else why it cannot be decoded.
std::string decodeExrRgb(const std::string& path, ir::TextureImage& image);

// "" when the Radiance .hdr file in `bytes` holds every row its resolution line
// promises (flat or run-length encoded, as stb_image reads them), else why not:
// stb_image reads a truncated file's missing texels as repeats of one texel.
std::string hdrTruncation(const std::vector<unsigned char>& bytes);

// The Radiance .hdr file's RGB, linear as stored, into `image`: "" on
// success, else why not (a truncated file among them).
std::string decodeHdrRgb(const std::string& path, ir::TextureImage& image);

}  // namespace sdfc
