#include "png_encode.h"

#include <zlib.h>

#include <stdexcept>
#include <vector>

namespace sdfc {
namespace {

void appendBigEndian(std::string& out, uint32_t value) {
  const char bytes[4] = {char(value >> 24), char(value >> 16), char(value >> 8), char(value)};
  out.append(bytes, 4);
}

// length, type, data, CRC-32 of type and data (PNG spec, 5.3)
void appendChunk(std::string& out, const char type[4], const std::string& data) {
  appendBigEndian(out, uint32_t(data.size()));
  const size_t type_at = out.size();
  out.append(type, 4);
  out += data;
  const auto* crc_from = reinterpret_cast<const Bytef*>(out.data() + type_at);
  appendBigEndian(out, uint32_t(crc32(0, crc_from, uInt(4 + data.size()))));
}

}  // namespace

std::string encodePng(const uint8_t* rgb, uint32_t width, uint32_t height) {
  // Each row: filter type 1 (Sub), then each byte minus the byte one pixel left.
  // On rendered images Sub compressed best of None/Sub/Up/Paeth at level 1.
  const size_t stride = size_t(width) * 3;
  std::vector<uint8_t> filtered((stride + 1) * height);
  for (uint32_t y = 0; y < height; ++y) {
    const uint8_t* row = rgb + y * stride;
    uint8_t* out = &filtered[y * (stride + 1)];
    out[0] = 1;
    for (size_t i = 0; i < stride; ++i) out[1 + i] = uint8_t(row[i] - (i >= 3 ? row[i - 3] : 0));
  }

  z_stream stream{};
  if (deflateInit2(&stream, 1, Z_DEFLATED, 15, 8, Z_DEFAULT_STRATEGY) != Z_OK)
    throw std::runtime_error("cannot encode PNG: zlib failed to start");
  std::string idat(deflateBound(&stream, uLong(filtered.size())), '\0');
  stream.next_in = filtered.data();
  stream.avail_in = uInt(filtered.size());
  stream.next_out = reinterpret_cast<Bytef*>(idat.data());
  stream.avail_out = uInt(idat.size());
  const int status = deflate(&stream, Z_FINISH);  // deflateBound: one call is enough
  idat.resize(stream.total_out);
  deflateEnd(&stream);
  if (status != Z_STREAM_END) throw std::runtime_error("cannot encode PNG: zlib failed");

  std::string ihdr;
  appendBigEndian(ihdr, width);
  appendBigEndian(ihdr, height);
  ihdr += std::string("\x08\x02\x00\x00\x00", 5);  // 8 bits, RGB, deflate, adaptive filters, no interlace
  std::string png("\x89PNG\r\n\x1a\n", 8);
  appendChunk(png, "IHDR", ihdr);
  appendChunk(png, "IDAT", idat);
  appendChunk(png, "IEND", "");
  return png;
}

}  // namespace sdfc
