// Images read at check time for texture(file: "..."): PNG (8 or 16 bits) or
// any other format stb_image reads, sRGB decoded to linear; EXR and Radiance
// .hdr linear, as stored.
// Like point files, the path is relative to the scene's folder, and a file
// too large for the shader's scene data is refused before it is decoded.
#pragma once
#include <memory>
#include <string>

#include "ir/scene.h"

namespace sdfc {

// The largest texture: 2048 x 2048 texels (64 MiB of scene data as vec4s, half
// of the 128 MiB the buffer may hold).
constexpr size_t kMaxTexturePixels = size_t(2048) * 2048;

struct ImageFile {
  std::shared_ptr<ir::TextureImage> image;  // null when it could not be read
  std::string reason;                       // why not
};

ImageFile readImageFile(const std::string& path);

}  // namespace sdfc
