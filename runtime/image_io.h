// Image files: PNG (8-bit sRGB, tone-mapped), EXR (linear float) and PFM
// (linear float), chosen by extension. Images are encoded in memory and written
// by writeFileAtomically (atomic_file.h), so a failed or interrupted write
// never leaves a half-written image.
// Also readers and comparison metrics for golden-image tests.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "float_image.h"

namespace sdfc {

// File problems (not device failures): unknown extension, unwritable path, bad file.
class ImageIoError : public std::runtime_error {
 public:
  explicit ImageIoError(const std::string& message) : std::runtime_error(message) {}
};

enum class ImageFormat { Png, Exr, Pfm };
// By extension, case-insensitive: .png, .exr, .pfm. Throws ImageIoError otherwise.
ImageFormat imageFormatFromPath(const std::string& path);

enum class ToneCurve {
  Clamp,       // `--tonemap linear`: radiance * 2^exposure, clamped to [0, 1] per channel
  AcesFit,     // Narkowicz 2015 fit of the ACES RRT+ODT: x(2.51x+.03) / (x(2.43x+.59)+.14)
  PbrNeutral,  // Khronos PBR Neutral (2024): identity below 0.76, a shoulder on the peak
               // channel towards 1 that keeps the hue, desaturating only what it compresses
};

// PNG and the view only; EXR and PFM store linear radiance untouched. The default
// is what `sdfc render` and `sdfc view` use, so every PNG writer agrees.
struct ToneMap {
  float exposure_stops = 0;  // radiance is multiplied by 2^exposure_stops first
  ToneCurve curve = ToneCurve::PbrNeutral;
};

// "linear" | "neutral" | "aces" -> the curve; nullopt for other names.
std::optional<ToneCurve> toneCurveFromName(const std::string& name);
const char* toneCurveName(ToneCurve curve);

// One pixel's linear RGB -> tone-mapped RGB in [0, 1], still linear (NaN and
// negatives count as 0). PBR Neutral works on the pixel, the others per channel.
void applyToneMap(const float linear[3], const ToneMap& tone_map, float out[3]);
// A grey value's channel: applyToneMap of (v, v, v).
float applyToneCurve(float linear, const ToneMap& tone_map);
float srgbEncode(float linear);                               // sRGB OETF (IEC 61966-2-1)
float srgbDecode(float encoded);                              // its inverse
// A tone-mapped value in [0, 1] -> its sRGB byte: round(clamp(srgbEncode(v)) * 255).
// srgb8Fast gives the same byte from a 256-entry threshold table (no pow).
uint8_t srgb8Direct(float tone_mapped);
uint8_t srgb8Fast(float tone_mapped);
// srgb8Fast's table: [k] = the smallest float whose byte is k ([0] = -1). The
// view's device tone map (display_pass.h) searches the same table.
const std::array<float, 256>& srgb8Thresholds();
// RGB8 bytes, row-major, top row first: tone curve, then sRGB OETF, rounded.
std::vector<uint8_t> toSrgb8(const FloatImage& image, const ToneMap& tone_map);

// Writes RGB (alpha is dropped: the renderer's alpha is always 1).
void writeImage(const std::string& path, const FloatImage& image, const ToneMap& tone_map = {});

// Reads PNG (or any 8-bit format stb_image knows; sRGB-decoded to linear, the tone
// curve is not inverted), EXR and PFM. Always RGBA; a = 1 where the file has none.
FloatImage readImage(const std::string& path);

// Metrics over the RGB channels of images of equal size (throws otherwise).
double rmse(const FloatImage& image, const FloatImage& reference);
// mean((a - b)^2 / (b^2 + 0.01)), b = reference.
double relMse(const FloatImage& image, const FloatImage& reference);

}  // namespace sdfc
