// PNG output (runtime/png_encode.h): every file decodes to exactly the bytes
// toSrgb8 made, and is smaller than stb's writer's file of the same bytes.
#include <gtest/gtest.h>

#include <stb_image.h>
#include <stb_image_write.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <unistd.h>
#include <zlib.h>

#include "image_io.h"
#include "png_encode.h"

namespace sdfc {
namespace {

namespace fs = std::filesystem;

// A render's look: smooth shading, a hard edge, and per-pixel noise (1 spp).
std::vector<uint8_t> renderLike(uint32_t w, uint32_t h, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, 6.0f);
  std::vector<uint8_t> rgb(size_t(w) * h * 3);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      const float dx = float(x) - w * 0.5f, dy = float(y) - h * 0.5f;
      const bool inside = dx * dx + dy * dy < 0.1f * float(w * w);
      for (int c = 0; c < 3; ++c) {
        const float base = inside ? 200.0f - 0.3f * float(y) - 20.0f * c : 40.0f + 0.1f * float(x);
        rgb[(size_t(y) * w + x) * 3 + c] = uint8_t(std::clamp(base + noise(rng), 0.0f, 255.0f));
      }
    }
  return rgb;
}

std::vector<uint8_t> decode(const std::string& png, uint32_t& w, uint32_t& h) {
  int iw = 0, ih = 0, channels = 0;
  unsigned char* data = stbi_load_from_memory(reinterpret_cast<const stbi_uc*>(png.data()), int(png.size()),
                                              &iw, &ih, &channels, 3);
  if (!data) return {};
  std::vector<uint8_t> bytes(data, data + size_t(iw) * ih * 3);
  stbi_image_free(data);
  w = uint32_t(iw);
  h = uint32_t(ih);
  EXPECT_EQ(channels, 3);
  return bytes;
}

TEST(PngEncode, DecodesToTheSameBytes) {
  std::mt19937 rng(7);
  for (auto [w, h] : {std::pair{1u, 1u}, {2u, 3u}, {7u, 5u}, {64u, 36u}, {641u, 17u}}) {
    std::vector<uint8_t> random(size_t(w) * h * 3);
    for (uint8_t& b : random) b = uint8_t(rng());
    for (const std::vector<uint8_t>& rgb : {random, renderLike(w, h, w * 31 + h)}) {
      uint32_t dw = 0, dh = 0;
      EXPECT_EQ(decode(encodePng(rgb.data(), w, h), dw, dh), rgb) << w << "x" << h;
      EXPECT_EQ(dw, w);
      EXPECT_EQ(dh, h);
    }
  }
}

// The IDAT chunks' zlib stream, inflated by zlib itself (which checks its
// Adler-32, as stb's decoder does not): its size, or -1 if it does not inflate.
long inflatedIdatSize(const std::string& png) {
  std::string stream;
  for (size_t at = 8; at + 12 <= png.size();) {
    const auto* p = reinterpret_cast<const unsigned char*>(png.data() + at);
    const size_t length = (size_t(p[0]) << 24) | (size_t(p[1]) << 16) | (size_t(p[2]) << 8) | p[3];
    if (png.compare(at + 4, 4, "IDAT") == 0) stream += png.substr(at + 8, length);
    at += 12 + length;
  }
  std::vector<Bytef> out(stream.size() * 4 + (size_t(1) << 22));
  uLongf out_size = uLongf(out.size());
  if (uncompress(out.data(), &out_size, reinterpret_cast<const Bytef*>(stream.data()), uLong(stream.size())) != Z_OK)
    return -1;
  return long(out_size);
}

TEST(PngEncode, LargeImagesDeflatedInTwoHalvesDecode) {
  // From 2^18 filtered bytes the stream is deflated in two halves on two
  // threads and joined: decoders must see one valid stream, its check intact.
  std::mt19937 rng(11);
  for (auto [w, h] : {std::pair{640u, 360u}, {1000u, 88u}, {1u, 90000u}, {4099u, 23u}}) {
    std::vector<uint8_t> random(size_t(w) * h * 3);
    for (uint8_t& b : random) b = uint8_t(rng());
    for (const std::vector<uint8_t>& rgb : {random, renderLike(w, h, w + h), std::vector<uint8_t>(random.size(), 9)}) {
      const std::string png = encodePng(rgb.data(), w, h);
      uint32_t dw = 0, dh = 0;
      EXPECT_EQ(decode(png, dw, dh), rgb) << w << "x" << h;
      EXPECT_EQ(inflatedIdatSize(png), long(size_t(w) * 3 + 1) * long(h)) << w << "x" << h;
    }
  }
}

TEST(PngEncode, WriteImageKeepsToSrgb8sBytes) {
  const fs::path dir = fs::temp_directory_path() / ("sdfc png encode test " + std::to_string(::getpid()));
  fs::create_directories(dir);
  FloatImage image(97, 41, 1.0f);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> radiance(-0.1f, 4.0f);
  for (float& v : image.rgba) v = radiance(rng);
  image.rgba[5] = std::nanf("");
  const std::string path = (dir / "a b.png").string();
  writeImage(path, image);  // the default tone curve, as `sdfc render`
  std::ifstream file(path, std::ios::binary);
  std::stringstream text;
  text << file.rdbuf();
  uint32_t w = 0, h = 0;
  EXPECT_EQ(decode(text.str(), w, h), toSrgb8(image, ToneMap{}));
  fs::remove_all(dir);
}

// stb's writer (level 8, the filter per row by least sum of bytes) wrote 18-24%
// more than zlib level 1 with Sub on renders (bench/results/fixed_costs.md).
TEST(PngEncode, SmallerThanStbsWriter) {
  const uint32_t w = 320, h = 180;
  const std::vector<uint8_t> like = renderLike(w, h, 1);
  FloatImage image(w, h, 1.0f);
  for (size_t i = 0; i < image.pixelCount(); ++i)
    for (int c = 0; c < 3; ++c) image.rgba[i * 4 + c] = srgbDecode(like[i * 3 + c] / 255.0f);
  const ToneMap linear{0.0f, ToneCurve::Clamp};
  const std::vector<uint8_t> rgb = toSrgb8(image, linear);
  std::string stb;
  auto append = [](void* context, void* data, int size) {
    static_cast<std::string*>(context)->append(static_cast<const char*>(data), size_t(size));
  };
  ASSERT_TRUE(stbi_write_png_to_func(append, &stb, int(w), int(h), 3, rgb.data(), int(w) * 3));
  const fs::path path = fs::temp_directory_path() / ("sdfc_png_size_" + std::to_string(::getpid()) + ".png");
  writeImage(path.string(), image, linear);
  const uintmax_t ours = fs::file_size(path);
  fs::remove(path);
  EXPECT_LT(ours, stb.size());
  EXPECT_GT(ours, stb.size() / 2);  // still a whole image, not a stub
}

}  // namespace
}  // namespace sdfc
