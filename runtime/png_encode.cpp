#include "png_encode.h"

#include <zlib.h>

#include <exception>
#include <stdexcept>
#include <system_error>
#include <thread>
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

// Raw deflate (no zlib header or check) of data[0, n) at level 1, primed with
// `dictionary` (the bytes before it, so its matches may reach back into them);
// ended with a sync flush (byte-aligned, not final) unless `last`.
std::string deflatePart(const uint8_t* data, size_t n, const uint8_t* dictionary, size_t dictionary_n, bool last) {
  z_stream stream{};
  if (deflateInit2(&stream, 1, Z_DEFLATED, -15, 8, Z_DEFAULT_STRATEGY) != Z_OK)
    throw std::runtime_error("cannot encode PNG: zlib failed to start");
  if (dictionary_n > 0 && deflateSetDictionary(&stream, dictionary, uInt(dictionary_n)) != Z_OK) {
    deflateEnd(&stream);
    throw std::runtime_error("cannot encode PNG: zlib failed");
  }
  // deflateBound covers the data; the sync flush adds at most 5 bytes (an empty stored block).
  std::string out(deflateBound(&stream, uLong(n)) + 16, '\0');
  stream.next_in = const_cast<Bytef*>(data);
  stream.avail_in = uInt(n);
  stream.next_out = reinterpret_cast<Bytef*>(out.data());
  stream.avail_out = uInt(out.size());
  const int status = deflate(&stream, last ? Z_FINISH : Z_SYNC_FLUSH);
  const bool done = last ? status == Z_STREAM_END : status == Z_OK && stream.avail_in == 0 && stream.avail_out > 0;
  out.resize(stream.total_out);
  deflateEnd(&stream);
  if (!done) throw std::runtime_error("cannot encode PNG: zlib failed");
  return out;
}

// The zlib stream (RFC 1950) of data[0, n): deflated in two halves on two threads
// when it is large, the second primed with the first's last 32 KiB (the window),
// joined as one deflate stream (the first ends with a sync flush) and checked by
// the halves' Adler-32s combined; pigz splits its input the same way.
std::string zlibStream(const uint8_t* data, size_t n) {
  constexpr size_t kWindow = 32768, kSplitFrom = size_t(1) << 18;
  std::string out("\x78\x01", 2);  // deflate, 32 KiB window, fastest level (FLEVEL 0)
  uLong adler = adler32(0L, Z_NULL, 0);
  const size_t half = n / 2;
  std::string second;
  uLong adler_second = 0;
  std::exception_ptr failed;
  std::thread worker;
  if (n >= kSplitFrom && std::thread::hardware_concurrency() >= 2) {
    try {
      worker = std::thread([&] {
        try {
          second = deflatePart(data + half, n - half, data + half - kWindow, kWindow, true);
          adler_second = adler32(adler32(0L, Z_NULL, 0), data + half, uInt(n - half));
        } catch (...) {
          failed = std::current_exception();
        }
      });
    } catch (const std::system_error&) {  // no thread to be had: one stream, as for a small image
    }
  }
  if (!worker.joinable()) {
    out += deflatePart(data, n, nullptr, 0, true);
    adler = adler32(adler, data, uInt(n));
  } else {
    std::string first;
    try {
      first = deflatePart(data, half, nullptr, 0, false);
    } catch (...) {
      worker.join();
      throw;
    }
    adler = adler32(adler, data, uInt(half));
    worker.join();
    if (failed) std::rethrow_exception(failed);
    out += first;
    out += second;
    adler = adler32_combine(adler, adler_second, z_off_t(n - half));
  }
  appendBigEndian(out, uint32_t(adler));
  return out;
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

  const std::string idat = zlibStream(filtered.data(), filtered.size());

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
