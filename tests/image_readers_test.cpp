// The image readers of texture(file:) and sky(map:) on the odd but valid
// corners of their formats (issue 47 item 10): an EXR stored bottom first, a
// truncated Radiance .hdr, NaN in an EXR texture, a 16-bit PNG, a .hdr
// texture brighter than 1, and maps too bright or too dim to render. The
// files are written here byte by byte, so each corner is exactly what is meant.
#include <gtest/gtest.h>
#include <stb_image_write.h>
#include <zlib.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <vector>

#include "check/env_map_file.h"
#include "check/image_file.h"
#include "image_io.h"

namespace sdfc {
namespace {

namespace fs = std::filesystem;

fs::path dir() {
  const fs::path d = fs::temp_directory_path() / "sdfc image_readers_test";
  fs::create_directories(d);
  return d;
}

void writeBytes(const fs::path& path, const std::vector<unsigned char>& bytes) {
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

template <typename T>
void put(std::vector<unsigned char>& out, T v) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));  // little-endian, as EXR is
  out.insert(out.end(), b, b + sizeof(T));
}

void putAttribute(std::vector<unsigned char>& out, const std::string& name, const std::string& type,
                  const std::vector<unsigned char>& value) {
  out.insert(out.end(), name.begin(), name.end());
  out.push_back(0);
  out.insert(out.end(), type.begin(), type.end());
  out.push_back(0);
  put(out, int32_t(value.size()));
  out.insert(out.end(), value.begin(), value.end());
}

// An uncompressed scan-line EXR of FLOAT R, G, B, its chunks stored in the
// file in the order `line_order` says (0 top first, 1 bottom first), the
// offset table by increasing y as the format has it.
void writeExr(const fs::path& path, int w, int h, int line_order, const std::function<float(int, int, int)>& value) {
  std::vector<unsigned char> out = {0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0};
  std::vector<unsigned char> channels;
  for (const char* name : {"B", "G", "R"}) {
    channels.push_back(uint8_t(name[0]));
    channels.push_back(0);
    put(channels, int32_t(2));  // FLOAT
    put(channels, int32_t(0));  // pLinear, reserved
    put(channels, int32_t(1));
    put(channels, int32_t(1));
  }
  channels.push_back(0);
  putAttribute(out, "channels", "chlist", channels);
  putAttribute(out, "compression", "compression", {0});
  std::vector<unsigned char> box;
  for (int32_t v : {0, 0, w - 1, h - 1}) put(box, v);
  putAttribute(out, "dataWindow", "box2i", box);
  putAttribute(out, "displayWindow", "box2i", box);
  putAttribute(out, "lineOrder", "lineOrder", {uint8_t(line_order)});
  std::vector<unsigned char> one, zero2;
  put(one, 1.0f);
  put(zero2, 0.0f);
  put(zero2, 0.0f);
  putAttribute(out, "pixelAspectRatio", "float", one);
  putAttribute(out, "screenWindowCenter", "v2f", zero2);
  putAttribute(out, "screenWindowWidth", "float", one);
  out.push_back(0);
  const size_t chunk = 8 + size_t(w) * 3 * 4;
  const size_t first = out.size() + size_t(h) * 8;
  for (int y = 0; y < h; ++y) put(out, uint64_t(first + chunk * size_t(line_order ? h - 1 - y : y)));
  for (int i = 0; i < h; ++i) {
    const int y = line_order ? h - 1 - i : i;
    put(out, int32_t(y));
    put(out, int32_t(w * 3 * 4));
    for (int c : {2, 1, 0})
      for (int x = 0; x < w; ++x) put(out, value(x, y, c));
  }
  writeBytes(path, out);
}

float rowValue(int x, int y, int c) { return float(1 + y * 10 + x) + 0.25f * float(c); }

TEST(ImageReaders, ExrStoredBottomFirstReadsTopFirst) {
  for (int order : {0, 1}) {
    SCOPED_TRACE(order ? "bottom first" : "top first");
    const fs::path path = dir() / ("order " + std::to_string(order) + ".exr");
    writeExr(path, 8, 4, order, rowValue);
    const ImageFile texture = readImageFile(path.string());
    const EnvMapFile map = readEnvMapFile(path.string());
    ASSERT_TRUE(texture.image) << texture.reason;
    ASSERT_TRUE(map.image) << map.reason;
    for (const ir::TextureImage* image : {texture.image.get(), map.image.get()})
      for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 8; ++x)
          for (int c = 0; c < 3; ++c) ASSERT_EQ(image->rgb[(size_t(y) * 8 + x) * 3 + c], rowValue(x, y, c)) << x << ", " << y;
    const FloatImage read = readImage(path.string());
    EXPECT_EQ(read.rgba[0], rowValue(0, 0, 0));
    EXPECT_EQ(read.rgba[(3 * 8 + 7) * 4 + 2], rowValue(7, 3, 2));
  }
}

// A Radiance file from stb's writer (run-length encoded at 8 texels wide and
// more, flat below), cut short.
fs::path writeHdr(const std::string& name, int w, int h, float value, size_t cut = 0) {
  const fs::path path = dir() / name;
  std::vector<float> texels(size_t(w) * h * 3, value);
  EXPECT_TRUE(stbi_write_hdr(path.c_str(), w, h, 3, texels.data()));
  if (cut) fs::resize_file(path, fs::file_size(path) - cut);
  return path;
}

// A data window whose size overflows 32 bits (found by fuzz/image_file_fuzz:
// 2 * -2147483646 in the map's 2:1 check, undefined behaviour) is refused by
// its size, as a texture and as a map.
TEST(ImageReaders, ExrDataWindowsBeyondIntAreRefused) {
  for (const std::vector<int32_t>& window : std::vector<std::vector<int32_t>>{
           {0, 2147483647, 3, 0}, {0, -2147483647 - 1, 3, 2147483647}, {2147483647, 0, -2147483647 - 1, 1}}) {
    const fs::path path = dir() / "window.exr";
    writeExr(path, 4, 2, 0, [](int, int, int) { return 0.5f; });
    std::ifstream in(path, std::ios::binary);
    std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string key = std::string("dataWindow") + '\0' + "box2i" + '\0';
    const size_t at = std::string(bytes.begin(), bytes.end()).find(key);
    ASSERT_NE(at, std::string::npos);
    std::memcpy(&bytes[at + key.size() + 4], window.data(), 16);
    writeBytes(path, bytes);
    const ImageFile texture = readImageFile(path.string());
    EXPECT_FALSE(texture.image);
    EXPECT_NE(texture.reason.find("its data window is"), std::string::npos) << texture.reason;
    const EnvMapFile map = readEnvMapFile(path.string());
    EXPECT_FALSE(map.image);
    EXPECT_NE(map.reason.find("its data window is"), std::string::npos) << map.reason;
  }
}

TEST(ImageReaders, TruncatedHdrIsRefused) {
  for (int w : {16, 4}) {
    SCOPED_TRACE(w);
    const fs::path whole = writeHdr("whole.hdr", w, w / 2, 0.5f);
    EXPECT_TRUE(readEnvMapFile(whole.string()).image);
    EXPECT_TRUE(readImageFile(whole.string()).image);
    const fs::path cut = writeHdr("cut.hdr", w, w / 2, 0.5f, 9);
    const EnvMapFile map = readEnvMapFile(cut.string());
    const ImageFile texture = readImageFile(cut.string());
    EXPECT_FALSE(map.image);
    EXPECT_FALSE(texture.image);
    const std::string rows = "it ends after " + std::to_string(w / 2 - 1) + " of its " + std::to_string(w / 2) + " rows";
    EXPECT_NE(map.reason.find(rows), std::string::npos) << map.reason;
    EXPECT_NE(texture.reason.find(rows), std::string::npos) << texture.reason;
  }
}

TEST(ImageReaders, NonFiniteExrTexelsAreRefusedInTextures) {
  const fs::path path = dir() / "nan texture.exr";
  writeExr(path, 4, 2, 0, [](int x, int y, int c) { return x == 2 && y == 1 && c == 1 ? std::nanf("") : 0.5f; });
  const ImageFile texture = readImageFile(path.string());
  EXPECT_FALSE(texture.image);
  EXPECT_NE(texture.reason.find("texel (2, 1) has G = nan; a colour must be finite (1 value is not)"), std::string::npos)
      << texture.reason;
}

// A 16-bit RGB PNG, its one IDAT deflated by zlib.
void writePng16(const fs::path& path, int w, int h, uint16_t value) {
  auto be32 = [](std::vector<unsigned char>& out, uint32_t v) {
    for (int s = 24; s >= 0; s -= 8) out.push_back(uint8_t(v >> s));
  };
  std::vector<unsigned char> out = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  auto chunk = [&](const char* type, const std::vector<unsigned char>& data) {
    be32(out, uint32_t(data.size()));
    std::vector<unsigned char> body(type, type + 4);
    body.insert(body.end(), data.begin(), data.end());
    out.insert(out.end(), body.begin(), body.end());
    be32(out, uint32_t(crc32(0, body.data(), uInt(body.size()))));
  };
  std::vector<unsigned char> ihdr;
  be32(ihdr, uint32_t(w));
  be32(ihdr, uint32_t(h));
  ihdr.insert(ihdr.end(), {16, 2, 0, 0, 0});  // 16 bits, RGB
  chunk("IHDR", ihdr);
  std::vector<unsigned char> raw;
  for (int y = 0; y < h; ++y) {
    raw.push_back(0);
    for (int i = 0; i < w * 3; ++i) raw.insert(raw.end(), {uint8_t(value >> 8), uint8_t(value & 255)});
  }
  uLongf size = compressBound(uLong(raw.size()));
  std::vector<unsigned char> idat(size);
  ASSERT_EQ(compress(idat.data(), &size, raw.data(), uLong(raw.size())), Z_OK);
  idat.resize(size);
  chunk("IDAT", idat);
  chunk("IEND", {});
  writeBytes(path, out);
}

TEST(ImageReaders, SixteenBitPngKeepsItsBits) {
  const fs::path path = dir() / "deep.png";
  const uint16_t value = 0x8000 + 100;  // between two 8-bit codes
  writePng16(path, 4, 2, value);
  const ImageFile texture = readImageFile(path.string());
  ASSERT_TRUE(texture.image) << texture.reason;
  const double v = value / 65535.0, linear = std::pow((v + 0.055) / 1.055, 2.4);
  EXPECT_NEAR(texture.image->rgb[5], linear, 1e-6);
}

TEST(ImageReaders, HdrTextureKeepsValuesAboveOne) {
  const fs::path path = writeHdr("bright texture.hdr", 8, 4, 4.0f);
  const ImageFile texture = readImageFile(path.string());
  ASSERT_TRUE(texture.image) << texture.reason;
  EXPECT_EQ(texture.image->rgb[0], 4.0f);  // RGBE holds 4 exactly; through 8 bits it was 1
}

TEST(ImageReaders, MapsOutsideTheRenderableRangeAreRefused) {
  const fs::path bright = dir() / "bright map.exr";
  writeExr(bright, 8, 4, 0, [](int x, int y, int c) { return x == 3 && y == 2 && c == 0 ? 1e30f : 1.0f; });
  const EnvMapFile b = readEnvMapFile(bright.string());
  EXPECT_FALSE(b.image);
  EXPECT_NE(b.reason.find("texel (3, 2) has R = 1e+30; sdfc takes radiances up to 1e+12"), std::string::npos)
      << b.reason;
  const fs::path dim = dir() / "dim map.exr";
  writeExr(dim, 8, 4, 0, [](int, int, int) { return 1e-40f; });
  const EnvMapFile d = readEnvMapFile(dim.string());
  EXPECT_FALSE(d.image);
  EXPECT_NE(d.reason.find("its brightest value is 9.99995e-41"), std::string::npos) << d.reason;
  const fs::path black = dir() / "black map.exr";
  writeExr(black, 8, 4, 0, [](int, int, int) { return 0.0f; });
  EXPECT_TRUE(readEnvMapFile(black.string()).image);  // black is a map, lit by nothing
}

}  // namespace
}  // namespace sdfc
