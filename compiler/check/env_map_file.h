// Environment maps read at check time for sky(map: "..."): an equirectangular
// HDR image, EXR (tinyexr) or Radiance .hdr (stb_image), linear as stored.
// Unlike a texture, a texel that is not a finite, non-negative radiance is an
// error (it would be a light of infinite or negative power), not clamped.
#pragma once
#include <memory>
#include <string>

#include "ir/scene.h"

namespace sdfc {

// The largest map: 4096 x 2048 texels, 32.5 MiB of scene data (a shared-
// exponent word a texel and the CDFs of a 512 x 256 grid; eval/env_map.h).
constexpr int kMaxEnvMapWidth = 4096;

struct EnvMapFile {
  std::shared_ptr<ir::TextureImage> image;  // null when it could not be used
  std::string reason;                       // why not
};

EnvMapFile readEnvMapFile(const std::string& path);

}  // namespace sdfc
