// Image files (PNG / EXR / PFM through the temp-and-rename writer), tone mapping
// and comparison metrics.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <random>
#include <string>

#include "image_io.h"

namespace sdfc {
namespace {

namespace fs = std::filesystem;

class RuntimeImageIo : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("sdfc_image_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
            "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  // Linear radiance spanning dark values, mid-tones, and > 1 (clipped in PNG).
  static FloatImage gradient(uint32_t w, uint32_t h) {
    FloatImage image(w, h, 1.0f);
    for (uint32_t y = 0; y < h; ++y)
      for (uint32_t x = 0; x < w; ++x) {
        float* p = image.at(x, y);
        p[0] = float(x) / (w - 1);
        p[1] = float(y) / (h - 1);
        p[2] = 0.001f * float(x + y) + 0.5f * (x == 0 ? 3.0f : 0.0f);
      }
    return image;
  }

  fs::path dir_;
};

TEST_F(RuntimeImageIo, ExrAndPfmRoundTripExactly) {
  const FloatImage image = gradient(19, 11);
  for (const char* name : {"a.exr", "a.pfm", "UPPER.PFM"}) {
    writeImage(path(name), image);
    EXPECT_FALSE(fs::exists(path(name) + ".tmp"));
    const FloatImage back = readImage(path(name));
    ASSERT_EQ(back.width, image.width) << name;
    ASSERT_EQ(back.height, image.height) << name;
    for (size_t i = 0; i < image.pixelCount(); ++i)
      for (int c = 0; c < 3; ++c) ASSERT_EQ(back.rgba[i * 4 + c], image.rgba[i * 4 + c]) << name;
  }
}

TEST_F(RuntimeImageIo, PngRoundTripWithinQuantisation) {
  const FloatImage image = gradient(33, 17);
  writeImage(path("a.png"), image, ToneMap{0.0f, ToneCurve::Clamp});  // the default is PBR Neutral
  EXPECT_FALSE(fs::exists(path("a.png.tmp")));
  const FloatImage back = readImage(path("a.png"));
  ASSERT_EQ(back.width, 33u);
  ASSERT_EQ(back.height, 17u);
  for (uint32_t y = 0; y < 17; ++y)
    for (uint32_t x = 0; x < 33; ++x)
      for (int c = 0; c < 3; ++c) {
        const float expected = std::min(image.at(x, y)[c], 1.0f);  // clamp curve
        // Half an 8-bit step in sRGB space, converted back to linear.
        const float encoded = srgbEncode(expected);
        const float tolerance =
            std::max(srgbDecode(std::min(encoded + 0.5f / 255, 1.0f)) - expected,
                     expected - srgbDecode(std::max(encoded - 0.5f / 255, 0.0f))) + 1e-6f;
        ASSERT_NEAR(back.at(x, y)[c], expected, tolerance) << x << "," << y << "," << c;
      }
}

TEST_F(RuntimeImageIo, RewritesReplaceAtomicallyAndFailuresLeaveNothing) {
  writeImage(path("r.exr"), gradient(4, 4));
  FloatImage other(4, 4, 0.25f);
  writeImage(path("r.exr"), other);
  EXPECT_EQ(readImage(path("r.exr")).rgba[0], 0.25f);

  EXPECT_THROW(writeImage(path("missing_dir/x.png"), other), ImageIoError);
  EXPECT_FALSE(fs::exists(path("missing_dir/x.png.tmp")));
  EXPECT_THROW(writeImage(path("x.bmp"), other), ImageIoError);
  EXPECT_THROW(writeImage(path("empty.png"), FloatImage()), ImageIoError);
  EXPECT_THROW(readImage(path("does_not_exist.exr")), ImageIoError);
  // Only r.exr remains: no temporaries.
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir_)) {
    ++files;
    EXPECT_EQ(entry.path().filename(), "r.exr");
  }
  EXPECT_EQ(files, 1);
}

TEST(RuntimeToneMap, CurvesAndSrgb) {
  EXPECT_EQ(srgbEncode(0.0f), 0.0f);
  EXPECT_NEAR(srgbEncode(1.0f), 1.0f, 1e-6f);
  EXPECT_NEAR(srgbEncode(0.18f), 0.4613f, 1e-3f);  // mid grey
  for (float v : {0.001f, 0.01f, 0.2f, 0.7f}) EXPECT_NEAR(srgbDecode(srgbEncode(v)), v, 1e-6f);

  ToneMap clamp;
  clamp.curve = ToneCurve::Clamp;
  EXPECT_EQ(applyToneCurve(2.0f, clamp), 1.0f);
  EXPECT_EQ(applyToneCurve(-1.0f, clamp), 0.0f);
  EXPECT_EQ(applyToneCurve(std::nanf(""), clamp), 0.0f);
  clamp.exposure_stops = 1;
  EXPECT_FLOAT_EQ(applyToneCurve(0.25f, clamp), 0.5f);

  ToneMap aces;
  aces.curve = ToneCurve::AcesFit;
  EXPECT_EQ(applyToneCurve(0.0f, aces), 0.0f);
  float previous = 0;
  for (float v = 0.01f; v < 100; v *= 1.5f) {  // monotonic, saturates at 1 (the fit
    const float t = applyToneCurve(v, aces);   // overshoots 1 near x = 10; clamped)
    EXPECT_GE(t, previous);
    if (t < 1.0f) {
      EXPECT_GT(t, previous);
    }
    EXPECT_LE(t, 1.0f);
    previous = t;
  }
  EXPECT_GT(previous, 0.99f);
}

// The default curve: Khronos PBR Neutral. Below its shoulder it is the identity
// less a small offset (at most 0.04), so a 0.6-albedo floor lit to 1.1 is not
// clipped to white as the clamp did (issue 29); above it the peak channel goes
// smoothly to 1 with the hue's order kept.
TEST(RuntimeToneMap, PbrNeutralHasAShoulder) {
  ToneMap neutral;
  EXPECT_EQ(neutral.curve, ToneCurve::PbrNeutral);  // the default
  EXPECT_EQ(applyToneCurve(0.0f, neutral), 0.0f);
  EXPECT_EQ(applyToneCurve(std::nanf(""), neutral), 0.0f);
  EXPECT_NEAR(applyToneCurve(0.5f, neutral), 0.46f, 1e-6f);
  EXPECT_NEAR(applyToneCurve(0.02f, neutral), 0.02f - 0.02f + 6.25f * 0.02f * 0.02f, 1e-7f);
  float previous = 0;
  for (float v = 0.001f; v < 1000; v *= 1.2f) {
    const float t = applyToneCurve(v, neutral);
    EXPECT_GT(t, previous) << v;
    EXPECT_LT(t, 1.0f) << v;
    previous = t;
  }
  EXPECT_GT(previous, 0.99f);
  // A bright orange stays orange: channels in order, none clipped.
  const float orange[3] = {3.0f, 1.5f, 0.3f};
  float out[3];
  applyToneMap(orange, neutral, out);
  EXPECT_GT(out[0], out[1]);
  EXPECT_GT(out[1], out[2]);
  EXPECT_LT(out[0], 1.0f);
  EXPECT_EQ(toneCurveFromName("neutral"), ToneCurve::PbrNeutral);
  EXPECT_EQ(toneCurveFromName("linear"), ToneCurve::Clamp);
  EXPECT_EQ(toneCurveFromName("aces"), ToneCurve::AcesFit);
  EXPECT_FALSE(toneCurveFromName("agx"));
}

TEST(RuntimeMetrics, RmseAndRelMse) {
  FloatImage a(8, 8, 0.5f), b(8, 8, 0.5f);
  EXPECT_EQ(rmse(a, b), 0.0);
  EXPECT_EQ(relMse(a, b), 0.0);
  for (float& v : a.rgba) v = 0.6f;
  EXPECT_NEAR(rmse(a, b), 0.1, 1e-6);
  EXPECT_NEAR(relMse(a, b), 0.01 / (0.25 + 0.01), 1e-6);
  a.at(0, 0)[3] = 100;  // alpha is ignored
  EXPECT_NEAR(rmse(a, b), 0.1, 1e-6);
  EXPECT_THROW(rmse(a, FloatImage(4, 4)), ImageIoError);
}

}  // namespace
}  // namespace sdfc

namespace sdfc {
namespace {

// toSrgb8's table search must give exactly the byte of the direct formula (PNG
// files and the view's presented frames depend on it): around every threshold and
// at a stride over all floats in [0, 1]; every float with SDFC_EXHAUSTIVE=1.
TEST(RuntimeImage, Srgb8TableMatchesDirectFormula) {
  const float one_f = 1.0f;
  uint32_t one;
  std::memcpy(&one, &one_f, sizeof one);
  const bool exhaustive = std::getenv("SDFC_EXHAUSTIVE") != nullptr;
  const uint32_t stride = exhaustive ? 1 : 509;
  auto at = [](uint32_t bits) {
    float f;
    std::memcpy(&f, &bits, sizeof f);
    return f;
  };
  size_t mismatches = 0, checked = 0;
  for (uint64_t bits = 0; bits <= one; bits += stride, ++checked)
    mismatches += srgb8Fast(at(uint32_t(bits))) != srgb8Direct(at(uint32_t(bits)));
  // Around each byte boundary: 64 floats either side of the first float of each byte.
  uint32_t previous = 0;
  for (uint64_t bits = 0; bits <= one; bits += 4096) {
    const uint8_t b = srgb8Direct(at(uint32_t(bits)));
    if (b != previous) {
      for (uint64_t x = bits > 8192 ? bits - 8192 : 0; x <= std::min<uint64_t>(bits + 64, one); ++x, ++checked)
        mismatches += srgb8Fast(at(uint32_t(x))) != srgb8Direct(at(uint32_t(x)));
      previous = b;
    }
  }
  EXPECT_EQ(mismatches, 0u) << "of " << checked;
  EXPECT_EQ(srgb8Fast(0.0f), 0);
  EXPECT_EQ(srgb8Fast(1.0f), 255);
  // Outside [0, 1] as srgb8Direct clamps: below 0 (and NaN) 0, above 1 255.
  for (float v : {-0.0f, -1e-30f, -3.0f, -std::numeric_limits<float>::infinity(), std::nanf(""),
                  std::numeric_limits<float>::denorm_min(), 1.0000001f, 7.5f, std::numeric_limits<float>::infinity()})
    EXPECT_EQ(srgb8Fast(v), srgb8Direct(std::isnan(v) ? 0.0f : v)) << v;

  // toSrgb8 as a whole (its tone curve has exp2 hoisted; its rows converted
  // on several threads) against the per-value formula.
  FloatImage image(97, 700);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> value(-1.0f, 20.0f);
  for (float& v : image.rgba) v = value(rng) * value(rng) / 20.0f;
  image.rgba[0] = std::nanf("");
  for (const ToneMap tone : {ToneMap{0.0f, ToneCurve::Clamp}, ToneMap{0.7f, ToneCurve::Clamp},
                             ToneMap{-1.3f, ToneCurve::AcesFit}, ToneMap{0.4f, ToneCurve::PbrNeutral}}) {
    const std::vector<uint8_t> bytes = toSrgb8(image, tone);
    size_t differing = 0;
    for (size_t i = 0; i < image.pixelCount(); ++i) {
      float mapped[3];
      applyToneMap(&image.rgba[i * 4], tone, mapped);
      for (int c = 0; c < 3; ++c) differing += bytes[i * 3 + c] != srgb8Direct(mapped[c]);
    }
    EXPECT_EQ(differing, 0u);
  }
}

}  // namespace
}  // namespace sdfc
