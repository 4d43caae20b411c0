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

// The brightest texel a map may have: a pixel's samples are summed per pass
// in fixed point with each term capped at 2^62 (runtime/sample_sum.h), so
// 1e12 leaves room for a million samples in a pass (a map of 1e30 rendered
// as the cap, 2^60 at 4 samples).
constexpr float kMaxEnvMapRadiance = 1e12f;
// The dimmest peak a map that is not black may have: the map is stored
// relative to its peak through a scale of peak / 32704 that must stay a normal
// float (a map of 1e-40 rendered black).
constexpr float kMinEnvMapPeak = 1e-30f;

struct EnvMapFile {
  std::shared_ptr<ir::TextureImage> image;  // null when it could not be used
  std::string reason;                       // why not
};

EnvMapFile readEnvMapFile(const std::string& path);

}  // namespace sdfc
