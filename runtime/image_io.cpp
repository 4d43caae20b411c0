#include "image_io.h"

#include "atomic_file.h"
#include "check/image_header.h"
#include "exr_channels.h"
#include "for_each_row.h"
#include "png_encode.h"

#include <stb_image.h>
#include <tinyexr.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <system_error>

namespace sdfc {
namespace {


std::vector<float> toRgb(const FloatImage& image) {
  std::vector<float> rgb(image.pixelCount() * 3);
  for (size_t i = 0; i < image.pixelCount(); ++i)
    for (int c = 0; c < 3; ++c) rgb[i * 3 + c] = image.rgba[i * 4 + c];
  return rgb;
}

// Little-endian PFM: negative scale; rows run bottom to top (PFM convention).
std::string encodePfm(const FloatImage& image) {
  std::string out = "PF\n" + std::to_string(image.width) + " " + std::to_string(image.height) + "\n-1.0\n";
  const std::vector<float> rgb = toRgb(image);
  static_assert(sizeof(float) == 4);
  for (uint32_t row = 0; row < image.height; ++row) {
    const float* line = &rgb[size_t(image.height - 1 - row) * image.width * 3];
    for (uint32_t i = 0; i < image.width * 3; ++i) {
      uint32_t bits;
      std::memcpy(&bits, &line[i], 4);
      const char bytes[4] = {char(bits), char(bits >> 8), char(bits >> 16), char(bits >> 24)};
      out.append(bytes, 4);
    }
  }
  return out;
}

FloatImage readPfm(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw ImageIoError("cannot open " + path);
  std::string magic;
  long width = 0, height = 0;
  double scale = 0;
  file >> magic >> width >> height >> scale;
  file.get();  // the single whitespace after the header
  const int channels = magic == "PF" ? 3 : magic == "Pf" ? 1 : 0;
  if (!file || channels == 0 || width <= 0 || height <= 0 || scale == 0)
    throw ImageIoError(path + ": not a PFM file");
  const uint32_t probe = 1;
  const bool host_little = *reinterpret_cast<const uint8_t*>(&probe) == 1;
  const bool swap = (scale < 0) != host_little;
  std::vector<float> data(size_t(width) * height * channels);
  file.read(reinterpret_cast<char*>(data.data()), std::streamsize(data.size() * 4));
  if (!file) throw ImageIoError(path + ": truncated PFM");
  FloatImage image{uint32_t(width), uint32_t(height), 1.0f};
  for (long y = 0; y < height; ++y)
    for (long x = 0; x < width; ++x)
      for (int c = 0; c < 3; ++c) {
        float value = data[(size_t(height - 1 - y) * width + x) * channels + (channels == 3 ? c : 0)];
        if (swap) {
          uint32_t bits;
          std::memcpy(&bits, &value, 4);
          bits = __builtin_bswap32(bits);
          std::memcpy(&value, &bits, 4);
        }
        image.at(uint32_t(x), uint32_t(y))[c] = value;
      }
  return image;
}

// The whole file in memory, so that one checked writer (atomic_file.h) puts
// it on disk: a short write or a full disk is an error, never a truncated file.
std::string encodeImage(ImageFormat format, const FloatImage& image, const ToneMap& tone_map) {
  switch (format) {
    case ImageFormat::Png: {
      const std::vector<uint8_t> bytes = toSrgb8(image, tone_map);
      try {
        return encodePng(bytes.data(), image.width, image.height);
      } catch (const std::runtime_error& error) {
        throw ImageIoError(error.what());
      }
    }
    case ImageFormat::Exr: {
      // One float channel each of R, G and B (exr_channels.h stores them sorted, B G R).
      const size_t n = image.pixelCount();
      std::vector<ExrChannel> channels{{"R", {}}, {"G", {}}, {"B", {}}};
      for (int c = 0; c < 3; ++c) {
        channels[c].values.resize(n);
        for (size_t i = 0; i < n; ++i) channels[c].values[i] = image.rgba[i * 4 + c];
      }
      return encodeExrChannels(image.width, image.height, std::move(channels));
    }
    case ImageFormat::Pfm: return encodePfm(image);
  }
  return {};
}

void checkSameSize(const FloatImage& a, const FloatImage& b) {
  if (a.width != b.width || a.height != b.height || a.rgba.size() != b.rgba.size())
    throw ImageIoError("image sizes differ: " + std::to_string(a.width) + "x" +
                       std::to_string(a.height) + " vs " + std::to_string(b.width) + "x" +
                       std::to_string(b.height));
}

}  // namespace

ImageFormat imageFormatFromPath(const std::string& path) {
  const std::string ext = lowerExtension(path);
  if (ext == ".png") return ImageFormat::Png;
  if (ext == ".exr") return ImageFormat::Exr;
  if (ext == ".pfm") return ImageFormat::Pfm;
  throw ImageIoError("unknown image extension '" + ext + "' (use .png, .exr or .pfm)");
}

std::optional<ToneCurve> toneCurveFromName(const std::string& name) {
  if (name == "linear") return ToneCurve::Clamp;
  if (name == "neutral") return ToneCurve::PbrNeutral;
  if (name == "aces") return ToneCurve::AcesFit;
  return std::nullopt;
}

const char* toneCurveName(ToneCurve curve) {
  switch (curve) {
    case ToneCurve::Clamp: return "linear";
    case ToneCurve::AcesFit: return "aces";
    case ToneCurve::PbrNeutral: return "neutral";
  }
  return "?";
}

namespace {

// The curve on exposed radiance (scale = 2^exposure taken once by the caller).
inline void toneMapScaled(const float* linear, float scale, ToneCurve curve, float* out) {
  float x[3];
  for (int c = 0; c < 3; ++c) {
    x[c] = linear[c] * scale;
    if (!(x[c] > 0)) x[c] = 0;  // also maps NaN to black
  }
  if (curve == ToneCurve::PbrNeutral) {
    // Khronos PBR Neutral tone mapping (Khronos 3D Formats WG, 2024), its published
    // formula: a toe that lifts the darkest channel's offset (at most 0.04), then
    // above start = 0.76 the peak channel p goes to 1 - d^2 / (p + d - start),
    // d = 1 - start, the others scaled alike (hue kept), blended towards white by
    // 1 - 1 / (0.15 (p - p') + 1) where the compression was strong.
    constexpr float kStart = 0.8f - 0.04f, kDesaturation = 0.15f;
    const float lo = std::min({x[0], x[1], x[2]});
    const float offset = lo < 0.08f ? lo - 6.25f * lo * lo : 0.04f;
    for (float& v : x) v -= offset;
    const float peak = std::max({x[0], x[1], x[2]});
    if (peak >= kStart) {
      constexpr float d = 1.0f - kStart;
      const float new_peak = 1.0f - d * d / (peak + d - kStart);
      const float g = 1.0f - 1.0f / (kDesaturation * (peak - new_peak) + 1.0f);
      for (float& v : x) v = v * (new_peak / peak) * (1.0f - g) + new_peak * g;
    }
    for (int c = 0; c < 3; ++c) out[c] = std::clamp(x[c], 0.0f, 1.0f);
    return;
  }
  for (int c = 0; c < 3; ++c) {
    float v = x[c];
    if (v > 0 && curve == ToneCurve::AcesFit)
      v = (v * (2.51f * v + 0.03f)) / (v * (2.43f * v + 0.59f) + 0.14f);  // Narkowicz 2015
    out[c] = std::min(v, 1.0f);
  }
}

}  // namespace

void applyToneMap(const float linear[3], const ToneMap& tone_map, float out[3]) {
  toneMapScaled(linear, std::exp2(tone_map.exposure_stops), tone_map.curve, out);
}

float applyToneCurve(float linear, const ToneMap& tone_map) {
  const float grey[3] = {linear, linear, linear};
  float out[3];
  applyToneMap(grey, tone_map, out);
  return out[0];
}

float srgbEncode(float linear) {
  if (!(linear > 0)) return 0;
  if (linear <= 0.0031308f) return 12.92f * linear;
  return 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

float srgbDecode(float encoded) {
  if (encoded <= 0.04045f) return encoded / 12.92f;
  return std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

uint8_t srgb8Direct(float tone_mapped) {
  return static_cast<uint8_t>(std::clamp(srgbEncode(tone_mapped), 0.0f, 1.0f) * 255.0f + 0.5f);
}

namespace {

float floatFromBits(uint32_t bits) {
  float f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}

}  // namespace

// thresholds[k] = the smallest float v in [0, 1] with srgb8Direct(v) >= k (k >= 1).
// srgb8Direct is monotone in v, so srgb8Fast(v) = the largest k with thresholds[k]
// <= v is the same byte without a pow per channel (an exhaustive check over every
// float in [0, 1] agrees; tests/runtime_image_test.cpp checks around each threshold).
const std::array<float, 256>& srgb8Thresholds() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    t[0] = -1.0f;
    uint32_t one;
    const float one_f = 1.0f;
    std::memcpy(&one, &one_f, sizeof one);
    for (int k = 1; k < 256; ++k) {
      // Non-negative floats are ordered like their bit patterns: bisect on those.
      uint32_t lo = 0, hi = one;  // srgb8Direct(0) = 0 < k, srgb8Direct(1) = 255 >= k
      while (hi - lo > 1) {
        const uint32_t mid = lo + (hi - lo) / 2;
        if (srgb8Direct(floatFromBits(mid)) >= k)
          hi = mid;
        else
          lo = mid;
      }
      t[k] = floatFromBits(hi);
    }
    return t;
  }();
  return table;
}

namespace {

// The byte of the first float of each run of 2^16 floats in [0, 1) (a float's
// top 16 bits: its exponent and 7 bits of mantissa), and the thresholds again
// with an infinite one after 255's. A run holds at most two thresholds (the
// curve is steepest near 0, where the runs are narrowest; checked as the
// table is built), so two steps without a branch go from a run's first byte
// to the value's: a binary search over the thresholds took 8 unpredictable
// branches a channel.
constexpr uint32_t kRunShift = 16, kOneBits = 0x3F800000u;

struct Srgb8Runs {
  std::array<uint8_t, (kOneBits >> kRunShift)> first{};
  std::array<float, 257> thresholds{};
};

const Srgb8Runs& srgb8Runs() {
  static const Srgb8Runs table = [] {
    const std::array<float, 256>& t = srgb8Thresholds();
    Srgb8Runs r;
    std::copy(t.begin(), t.end(), r.thresholds.begin());
    r.thresholds[256] = std::numeric_limits<float>::infinity();
    int k = 0;
    for (uint32_t run = 0; run < r.first.size(); ++run) {
      const float first = floatFromBits(run << kRunShift), last = floatFromBits(((run + 1) << kRunShift) - 1);
      while (k < 255 && t[k + 1] <= first) ++k;
      r.first[run] = uint8_t(k);
      int end = k;
      while (end < 255 && t[end + 1] <= last) ++end;
      if (end - k > 2) throw std::logic_error("srgb8Runs: a run holds more than two sRGB thresholds");
    }
    return r;
  }();
  return table;
}

}  // namespace

uint8_t srgb8Fast(float tone_mapped) {
  if (!(tone_mapped > 0.0f)) return 0;  // negative, zero or NaN
  if (tone_mapped >= 1.0f) return 255;
  const Srgb8Runs& r = srgb8Runs();
  uint32_t bits;
  std::memcpy(&bits, &tone_mapped, sizeof bits);
  int k = r.first[bits >> kRunShift];
  k += r.thresholds[k + 1] <= tone_mapped;
  k += r.thresholds[k + 1] <= tone_mapped;
  return static_cast<uint8_t>(k);
}

std::vector<uint8_t> toSrgb8(const FloatImage& image, const ToneMap& tone_map) {
  std::vector<uint8_t> bytes(image.pixelCount() * 3);
  srgb8Fast(0.5f);  // its tables built once, before the loops
  // applyToneMap with its exp2 taken once: the same operations, the same floats.
  const float scale = std::exp2(tone_map.exposure_stops);
  // Each pixel by itself, so rows on several threads give the same bytes (a
  // 640 x 360 image's ~20 ms of branchy tone curve, halved on two cores).
  forEachRow(int(image.height), [&](int y) {
    for (size_t i = size_t(y) * image.width; i < size_t(y + 1) * image.width; ++i) {
      float mapped[3];
      toneMapScaled(&image.rgba[i * 4], scale, tone_map.curve, mapped);
      for (int c = 0; c < 3; ++c) bytes[i * 3 + c] = srgb8Fast(mapped[c]);
    }
  });
  return bytes;
}

void writeImage(const std::string& path, const FloatImage& image, const ToneMap& tone_map) {
  const ImageFormat format = imageFormatFromPath(path);
  if (image.width == 0 || image.height == 0 || image.rgba.size() != image.pixelCount() * 4)
    throw ImageIoError("cannot write an empty or malformed image to " + path);
  try {
    writeFileAtomically(path, encodeImage(format, image, tone_map));
  } catch (const FileWriteError& error) {
    throw ImageIoError(error.what());
  }
}

FloatImage readImage(const std::string& path) {
  const std::string ext = lowerExtension(path);
  if (ext == ".pfm") return readPfm(path);
  if (ext == ".exr") {
    std::vector<float> rgba;
    int width = 0, height = 0;
    // Rows top first whatever the file's line order (check/image_header.h).
    if (const std::string why = decodeExrRgba(path, rgba, width, height); !why.empty())
      throw ImageIoError("cannot read EXR " + path + ": " + why);
    FloatImage image{uint32_t(width), uint32_t(height)};
    std::copy(rgba.begin(), rgba.end(), image.rgba.begin());
    return image;
  }
  int width = 0, height = 0, channels = 0;
  unsigned char* data = stbi_load(path.c_str(), &width, &height, &channels, 4);
  if (!data) throw ImageIoError("cannot read " + path + ": " + stbi_failure_reason());
  FloatImage image{uint32_t(width), uint32_t(height)};
  for (size_t i = 0; i < image.pixelCount(); ++i) {
    for (int c = 0; c < 3; ++c) image.rgba[i * 4 + c] = srgbDecode(data[i * 4 + c] / 255.0f);
    image.rgba[i * 4 + 3] = data[i * 4 + 3] / 255.0f;
  }
  stbi_image_free(data);
  return image;
}

double rmse(const FloatImage& image, const FloatImage& reference) {
  checkSameSize(image, reference);
  double sum = 0;
  for (size_t i = 0; i < image.pixelCount(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double d = double(image.rgba[i * 4 + c]) - reference.rgba[i * 4 + c];
      sum += d * d;
    }
  return image.pixelCount() ? std::sqrt(sum / (image.pixelCount() * 3.0)) : 0.0;
}

double relMse(const FloatImage& image, const FloatImage& reference) {
  checkSameSize(image, reference);
  double sum = 0;
  for (size_t i = 0; i < image.pixelCount(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double b = reference.rgba[i * 4 + c];
      const double d = double(image.rgba[i * 4 + c]) - b;
      sum += d * d / (b * b + 0.01);
    }
  return image.pixelCount() ? sum / (image.pixelCount() * 3.0) : 0.0;
}

}  // namespace sdfc
