#include "check/env_map_file.h"

#include "check/image_header.h"

#include <stb_image.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>

namespace sdfc {
namespace {

// The size is checked from the header, before the pixels are decoded.
std::string badSize(int w, int h) {
  std::ostringstream s;
  if (w != 2 * h)
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
    float* data = stbi_loadf(path.c_str(), &w, &h, &channels, 3);
    if (!data) {
      out.reason = std::string("it cannot be decoded (") + stbi_failure_reason() + ")";
      return out;
    }
    image->width = w;
    image->height = h;
    image->rgb.assign(data, data + size_t(w) * h * 3);
    stbi_image_free(data);
  } else {
    out.reason = "an environment map is an HDR image: an .exr or .hdr file";
    return out;
  }
  // Every texel a finite, non-negative radiance: name the first that is not.
  size_t bad = 0, first = 0;
  for (size_t i = 0; i < image->rgb.size(); ++i)
    if (!std::isfinite(image->rgb[i]) || image->rgb[i] < 0) {
      if (bad++ == 0) first = i;
    }
  if (bad) {
    const size_t texel = first / 3;
    std::ostringstream s;
    s << "texel (" << texel % image->width << ", " << texel / image->width << ") has "
      << "RGB"[first % 3] << " = " << image->rgb[first] << "; a radiance must be finite and non-negative ("
      << bad << (bad == 1 ? " value is not)" : " values are not)");
    out.reason = s.str();
    return out;
  }
  out.image = std::move(image);
  return out;
}

}  // namespace sdfc
