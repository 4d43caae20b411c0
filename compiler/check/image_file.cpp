#include "check/image_file.h"

#include "check/image_header.h"

#include <stb_image.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>

namespace sdfc {
namespace {

// The sRGB EOTF (IEC 61966-2-1).
float srgbToLinear(float v) { return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f); }

std::string tooLarge(int w, int h) {
  return "it is " + std::to_string(w) + " x " + std::to_string(h) + " texels; at most " +
         std::to_string(kMaxTexturePixels) + " (2048 x 2048) fit the shader's scene data";
}

}  // namespace

ImageFile readImageFile(const std::string& path) {
  ImageFile out;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    out.reason = std::filesystem::exists(path, ec) ? "it is not a regular file" : "no such file";
    return out;
  }
  auto image = std::make_shared<ir::TextureImage>();
  image->path = path;
  if (lowerExtension(path) == ".exr") {
    int w = 0, h = 0;
    out.reason = exrSizeFromHeader(path, w, h);
    if (!out.reason.empty()) return out;
    if (size_t(w) * size_t(h) > kMaxTexturePixels) {
      out.reason = tooLarge(w, h);
      return out;
    }
    out.reason = decodeExrRgb(path, *image);
    if (!out.reason.empty()) return out;
    // A NaN or infinite colour is refused as a map's radiance is (it was read
    // as 0 without a word); a negative one is clamped to 0.
    size_t bad = 0, first = 0;
    for (size_t i = 0; i < image->rgb.size(); ++i) {
      float& v = image->rgb[i];
      if (!std::isfinite(v)) {
        if (bad++ == 0) first = i;
      } else {
        v = std::max(v, 0.0f);
      }
    }
    if (bad) {
      std::ostringstream s;
      s << "texel (" << first / 3 % image->width << ", " << first / 3 / image->width << ") has "
        << "RGB"[first % 3] << " = " << image->rgb[first] << "; a colour must be finite (" << bad
        << (bad == 1 ? " value is not)" : " values are not)");
      out.reason = s.str();
      return out;
    }
  } else {
    int w = 0, h = 0, channels = 0;
    if (!stbi_info(path.c_str(), &w, &h, &channels)) {
      out.reason = std::string("it is not an image stb_image reads (") + stbi_failure_reason() + ")";
      return out;
    }
    if (size_t(w) * size_t(h) > kMaxTexturePixels) {
      out.reason = tooLarge(w, h);
      return out;
    }
    if (stbi_is_hdr(path.c_str())) {
      // Radiance .hdr: linear floats as stored, not through 8 bits (4.0 read as 1.0).
      out.reason = decodeHdrRgb(path, *image);
      if (!out.reason.empty()) return out;
    } else if (stbi_is_16_bit(path.c_str())) {
      // 16-bit PNG: all 16 bits decoded from sRGB (they were cut to 8).
      stbi_us* data = stbi_load_16(path.c_str(), &w, &h, &channels, 3);
      if (!data) {
        out.reason = std::string("it cannot be decoded (") + stbi_failure_reason() + ")";
        return out;
      }
      image->width = w;
      image->height = h;
      image->rgb.resize(size_t(w) * h * 3);
      for (size_t i = 0; i < image->rgb.size(); ++i) image->rgb[i] = srgbToLinear(data[i] / 65535.0f);
      stbi_image_free(data);
    } else {
      unsigned char* data = stbi_load(path.c_str(), &w, &h, &channels, 3);
      if (!data) {
        out.reason = std::string("it cannot be decoded (") + stbi_failure_reason() + ")";
        return out;
      }
      image->width = w;
      image->height = h;
      image->rgb.resize(size_t(w) * h * 3);
      for (size_t i = 0; i < image->rgb.size(); ++i) image->rgb[i] = srgbToLinear(data[i] / 255.0f);
      stbi_image_free(data);
    }
  }
  out.image = std::move(image);
  return out;
}

}  // namespace sdfc
