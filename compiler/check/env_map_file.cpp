#include "check/env_map_file.h"

#include "check/image_header.h"

#include <stb_image.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <sstream>

namespace sdfc {
namespace {

// The size is checked from the header, before the pixels are decoded.
std::string badSize(int w, int h) {
  std::ostringstream s;
  if (int64_t(w) != 2 * int64_t(h))
    s << "it is " << w << " x " << h << " texels, not 2:1 (an equirectangular map is twice as wide as high)";
  else if (w > kMaxEnvMapWidth)
    s << "it is " << w << " x " << h << " texels; at most " << kMaxEnvMapWidth << " x " << kMaxEnvMapWidth / 2
      << " fit the shader's scene data";
  else if (w < 4)
    s << "it is " << w << " x " << h << " texels; at least 4 x 2";
  return s.str();
}

}  // namespace

EnvMapFile readEnvMapFile(const std::string& path) {
  EnvMapFile out;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    out.reason = std::filesystem::exists(path, ec) ? "it is not a regular file" : "no such file";
    return out;
  }
  auto image = std::make_shared<ir::TextureImage>();
  image->path = path;
  const std::string ext = lowerExtension(path);
  if (ext == ".exr") {
    int w = 0, h = 0;
    out.reason = exrSizeFromHeader(path, w, h);
    if (!out.reason.empty()) return out;
    out.reason = badSize(w, h);
    if (!out.reason.empty()) return out;
    out.reason = decodeExrRgb(path, *image);
    if (!out.reason.empty()) return out;
  } else if (ext == ".hdr") {
    int w = 0, h = 0, channels = 0;
    if (!stbi_info(path.c_str(), &w, &h, &channels) || !stbi_is_hdr(path.c_str())) {
      out.reason = "it is not a Radiance HDR image";
      return out;
    }
    out.reason = badSize(w, h);
    if (!out.reason.empty()) return out;
    out.reason = decodeHdrRgb(path, *image);
    if (!out.reason.empty()) return out;
  } else {
    out.reason = "an environment map is an HDR image: an .exr or .hdr file";
    return out;
  }
  // Every texel a finite, non-negative radiance within the renderer's range:
  // name the first that is not.
  size_t bad = 0, first = 0, huge = 0, first_huge = 0;
  float peak = 0;
  for (size_t i = 0; i < image->rgb.size(); ++i) {
    const float v = image->rgb[i];
    if (!std::isfinite(v) || v < 0) {
      if (bad++ == 0) first = i;
    } else if (v > kMaxEnvMapRadiance) {
      if (huge++ == 0) first_huge = i;
    } else {
      peak = std::max(peak, v);
    }
  }
  auto texel = [&](size_t i) {
    std::ostringstream s;
    s << "texel (" << i / 3 % image->width << ", " << i / 3 / image->width << ") has " << "RGB"[i % 3] << " = "
      << image->rgb[i];
    return s.str();
  };
  if (bad) {
    std::ostringstream s;
    s << texel(first) << "; a radiance must be finite and non-negative (" << bad
      << (bad == 1 ? " value is not)" : " values are not)");
    out.reason = s.str();
    return out;
  }
  if (huge) {
    std::ostringstream s;
    s << texel(first_huge) << "; sdfc takes radiances up to " << kMaxEnvMapRadiance
      << " (a pixel's sums hold no more) (" << huge
      << (huge == 1 ? " value is over)" : " values are over)");
    out.reason = s.str();
    return out;
  }
  // The peak is stored at the shared exponent's top, through a float scale
  // that must stay a normal float: a map whose brightest texel is below
  // kMinEnvMapPeak would render black.
  if (peak > 0 && peak < kMinEnvMapPeak) {
    std::ostringstream s;
    s << "its brightest value is " << peak << "; a map brighter than black must reach " << kMinEnvMapPeak
      << " somewhere (a dimmer one renders black): scale its values, and sky(strength:) if needed";
    out.reason = s.str();
    return out;
  }
  out.image = std::move(image);
  return out;
}

}  // namespace sdfc
