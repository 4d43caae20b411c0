#include "shard_file.h"

#include <tinyexr.h>

#include <algorithm>
#include <charconv>
#include <climits>
#include <cmath>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <cerrno>
#include <fcntl.h>
#include <filesystem>
#include <sys/stat.h>
#include <unistd.h>
#include <map>
#include <memory>

namespace sdfc::farm {
namespace {

constexpr const char* kPrefix = "sdfc.";
constexpr int kWords = 4;  // 32-bit words per SampleSum
constexpr long long kMaxShardSide = 16384;  // `render --size`'s largest side

// The sum channels' names "sum.<c>.<word>"; c's index in a pixel's sums.
const char* const kSumNames[] = {"R", "G", "B", "Y2"};
int sumIndex(const std::string& c) {
  for (int i = 0; i < 4; ++i)
    if (c == kSumNames[i]) return i;
  return -1;
}
int rgbIndex(char c) { return c == 'R' ? 0 : c == 'G' ? 1 : 2; }

std::map<std::string, std::string> toAttributes(const ShardHeader& h) {
  return {{"format", std::to_string(kShardFormat)},
          {"layers", h.layers ? "1" : "0"},
          {"scene_hash", h.scene_hash},
          {"kernel_hash", h.kernel_hash},
          {"version", h.version},
          {"device", h.device},
          {"driver", h.driver},
          {"settings", h.settings},
          {"width", std::to_string(h.width)},
          {"height", std::to_string(h.height)},
          {"seed", std::to_string(h.seed)},
          {"spp", std::to_string(h.spp)},
          {"samples_per_pass", std::to_string(h.samples_per_pass)},
          {"slices", std::to_string(h.slices)},
          {"slice", std::to_string(h.slice)},
          {"frame", std::to_string(h.frame)},
          {"time", [&] { char t[32]; std::snprintf(t, sizeof t, "%.17g", h.time); return std::string(t); }()},
          {"sample_begin", std::to_string(h.samples.begin)},
          {"sample_end", std::to_string(h.samples.end)}};
}

ShardHeader fromAttributes(const std::map<std::string, std::string>& a, const std::string& path) {
  auto get = [&](const char* key) -> const std::string& {
    auto it = a.find(key);
    if (it == a.end())
      throw FarmError(path + ": not an sdfc shard (no '" + kPrefix + key + "' attribute)");
    return it->second;
  };
  // Whole decimal numbers only, range-checked: a header is read from a file that
  // may be damaged, and a wrapped or half-parsed value would merge wrong images.
  auto integer = [&](const char* key, long long lo, long long hi) -> long long {
    const std::string& s = get(key);
    long long value = 0;
    const auto [end, error] = std::from_chars(s.data(), s.data() + s.size(), value);
    if (error != std::errc() || end != s.data() + s.size() || s.empty() || value < lo || value > hi)
      throw FarmError(path + ": attribute '" + kPrefix + key + "' is not a whole number from " +
                      std::to_string(lo) + " to " + std::to_string(hi) + ": '" + s + "'");
    return value;
  };
  auto count = [&](const char* key, long long lo = 0) { return uint32_t(integer(key, lo, UINT32_MAX)); };
  ShardHeader h;
  h.scene_hash = get("scene_hash");
  // Before any other field: an older file may lack them, or mean other things by them.
  if (!a.count("format"))
    throw FarmError(path + ": a shard of an older sdfc (shard format 1, no '" + kPrefix +
                    "format' attribute); this sdfc merges format " + std::to_string(kShardFormat) +
                    " only: render the shard again");
  if (get("format") != std::to_string(kShardFormat))
    throw FarmError(path + ": shard format '" + get("format") + "'; this sdfc merges format " +
                    std::to_string(kShardFormat) + " only: render the shard again with this sdfc");
  h.layers = integer("layers", 0, 1) == 1;
  h.kernel_hash = get("kernel_hash");
  h.version = get("version");
  h.device = get("device");
  h.driver = get("driver");
  h.settings = get("settings");
  h.width = uint32_t(integer("width", 1, kMaxShardSide));
  h.height = uint32_t(integer("height", 1, kMaxShardSide));
  h.seed = count("seed");
  h.spp = count("spp", 1);
  h.samples_per_pass = count("samples_per_pass", 1);
  h.slices = count("slices", 1);
  h.slice = count("slice");
  h.frame = int(integer("frame", kNoFrame, INT_MAX));
  {
    const std::string& s = get("time");
    char* end = nullptr;
    h.time = s.empty() ? 0 : std::strtod(s.c_str(), &end);
    if (s.empty() || end != s.c_str() + s.size() || !std::isfinite(h.time) ||
        std::isspace(static_cast<unsigned char>(s[0])))
      throw FarmError(path + ": attribute '" + kPrefix + "time' is not a finite number: '" + s + "'");
  }
  h.samples.begin = count("sample_begin");
  h.samples.end = count("sample_end");
  if (h.samples.end < h.samples.begin || h.samples.end > h.spp)
    throw FarmError(path + ": bad sample range [" + std::to_string(h.samples.begin) + ", " +
                    std::to_string(h.samples.end) + ") of " + std::to_string(h.spp) + " spp");
  return h;
}

struct HeaderGuard {
  EXRHeader header;
  bool parsed = false;
  HeaderGuard() { InitEXRHeader(&header); }
  ~HeaderGuard() {
    if (parsed) FreeEXRHeader(&header);
  }
};

}  // namespace

std::string notAShard(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code error;
  const fs::file_status link = fs::symlink_status(path, error);
  if (!fs::exists(link)) return "no such file";
  const fs::file_status status = fs::status(path, error);
  if (error == std::errc::too_many_symbolic_link_levels)
    return "a symbolic link that loops (it leads back to itself), not a shard file";
  if (!fs::exists(status)) {
    if (fs::is_symlink(link)) return "a symbolic link to nothing (no such file)";
    return "cannot be read (" + error.message() + ")";
  }
  if (fs::is_directory(status)) return "a directory, not a shard file";
  if (!fs::is_regular_file(status)) return "not a regular file (a FIFO, device or socket), not a shard file";
  if (::access(path.c_str(), R_OK) != 0) return std::string("cannot be read (") + std::strerror(errno) + ")";
  return "";
}

namespace {

void parseHeader(const std::string& path, HeaderGuard& g) {
  EXRVersion version;
  if (const std::string why = notAShard(path); !why.empty()) throw FarmError(path + ": " + why);
  if (ParseEXRVersionFromFile(&version, path.c_str()) != TINYEXR_SUCCESS)
    throw FarmError(path + ": not an EXR file");
  const char* err = nullptr;
  if (ParseEXRHeaderFromFile(&g.header, &version, path.c_str(), &err) != TINYEXR_SUCCESS) {
    const std::string message = err ? err : "unreadable header";
    FreeEXRErrorMessage(err);
    throw FarmError(path + ": " + message);
  }
  g.parsed = true;
}

ShardHeader headerFrom(const EXRHeader& header, const std::string& path) {
  std::map<std::string, std::string> attributes;
  for (int i = 0; i < header.num_custom_attributes; ++i) {
    const EXRAttribute& a = header.custom_attributes[i];
    if (std::strncmp(a.name, kPrefix, std::strlen(kPrefix)) != 0) continue;
    attributes[a.name + std::strlen(kPrefix)] =
        std::string(reinterpret_cast<const char*>(a.value), size_t(std::max(a.size, 0)));
  }
  return fromAttributes(attributes, path);
}

}  // namespace

std::string fingerprint(const void* data, size_t size) {
  uint64_t h = 1469598103934665603ull;
  const auto* bytes = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < size; ++i) h = (h ^ bytes[i]) * 1099511628211ull;
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
  return text;
}

std::string headerMismatch(const ShardHeader& a, const ShardHeader& b) {
  const auto x = toAttributes(a), y = toAttributes(b);
  for (const char* key : {"layers", "scene_hash", "kernel_hash", "version", "device", "driver", "settings", "width",
                          "height", "seed", "spp", "samples_per_pass"})
    if (x.at(key) != y.at(key)) return std::string(key) + ": '" + x.at(key) + "' vs '" + y.at(key) + "'";
  return "";
}

void writeShard(const std::string& path, const ShardImage& shard) {
  const ShardHeader& h = shard.header;
  const size_t pixels = size_t(h.width) * h.height;
  const uint32_t stride = h.sumsPerPixel();
  if (pixels == 0 || shard.sums.size() != pixels * stride)
    throw FarmError("writeShard: " + std::to_string(shard.sums.size()) + " sums for a " +
                    std::to_string(h.width) + "x" + std::to_string(h.height) + " image");
  // Every channel as (name, type, 32-bit words), stored sorted by name.
  struct Plane {
    std::string name;
    int type;
    std::vector<uint32_t> words;
  };
  std::vector<Plane> planes;
  for (const char* c : {"R", "G", "B"}) {
    Plane plane{c, TINYEXR_PIXELTYPE_FLOAT, std::vector<uint32_t>(pixels)};
    for (size_t p = 0; p < pixels; ++p) {
      const float mean = sampleMean(shard.sums[p * stride + rgbIndex(c[0])], h.samples.count());
      std::memcpy(&plane.words[p], &mean, 4);
    }
    planes.push_back(std::move(plane));
  }
  for (uint32_t c = 0; c < stride; ++c)
    for (int w = 0; w < kWords; ++w) {
      Plane plane{std::string("sum.") + kSumNames[c] + "." + std::to_string(w), TINYEXR_PIXELTYPE_UINT,
                  std::vector<uint32_t>(pixels)};
      for (size_t p = 0; p < pixels; ++p)
        plane.words[p] = uint32_t(static_cast<unsigned __int128>(shard.sums[p * stride + c]) >> (32 * w));
      planes.push_back(std::move(plane));
    }
  for (const ExrChannel& f : shard.features) {
    if (f.values.size() != pixels || f.name.empty() || f.name.size() > 255 || f.name == "R" || f.name == "G" ||
        f.name == "B" || f.name.rfind("sum.", 0) == 0)
      throw FarmError("writeShard: channel '" + f.name + "' has the wrong size or name");
    Plane plane{f.name, TINYEXR_PIXELTYPE_FLOAT, std::vector<uint32_t>(pixels)};
    std::memcpy(plane.words.data(), f.values.data(), pixels * 4);
    planes.push_back(std::move(plane));
  }
  std::sort(planes.begin(), planes.end(), [](const Plane& a, const Plane& b) { return a.name < b.name; });
  const int channels = int(planes.size());
  std::vector<unsigned char*> pointers(channels);
  for (int c = 0; c < channels; ++c) pointers[c] = reinterpret_cast<unsigned char*>(planes[c].words.data());

  EXRHeader header;
  InitEXRHeader(&header);
  std::vector<EXRChannelInfo> infos(channels);
  std::vector<int> types(channels);
  for (int c = 0; c < channels; ++c) {
    std::memset(&infos[c], 0, sizeof infos[c]);
    std::strncpy(infos[c].name, planes[c].name.c_str(), 255);
    types[c] = planes[c].type;
  }
  header.num_channels = channels;
  header.channels = infos.data();
  header.pixel_types = types.data();
  header.requested_pixel_types = types.data();
  header.compression_type = TINYEXR_COMPRESSIONTYPE_ZIP;  // 2.4x smaller than none on the sum words
  const auto attributes = toAttributes(h);
  std::vector<EXRAttribute> custom(attributes.size());
  std::vector<std::string> values;
  values.reserve(attributes.size());
  size_t i = 0;
  for (const auto& [key, value] : attributes) {
    std::memset(&custom[i], 0, sizeof custom[i]);
    std::snprintf(custom[i].name, sizeof custom[i].name, "%s%s", kPrefix, key.c_str());
    std::snprintf(custom[i].type, sizeof custom[i].type, "string");
    values.push_back(value);
    custom[i].value = reinterpret_cast<unsigned char*>(values.back().data());
    custom[i].size = int(value.size());
    ++i;
  }
  header.num_custom_attributes = int(custom.size());
  header.custom_attributes = custom.data();

  EXRImage image;
  InitEXRImage(&image);
  image.images = pointers.data();
  image.width = int(h.width);
  image.height = int(h.height);
  image.num_channels = channels;

  const std::string temporary = path + ".tmp";
  const char* err = nullptr;
  if (SaveEXRImageToFile(&image, &header, temporary.c_str(), &err) != TINYEXR_SUCCESS) {
    const std::string message = err ? err : "unknown error";
    FreeEXRErrorMessage(err);
    std::remove(temporary.c_str());
    throw FarmError("cannot write shard " + path + ": " + message);
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) throw FarmError("cannot write shard " + path + ": " + error.message());
}

namespace {
ShardHeader::Stamp stampOf(const struct stat& st) {
  return {uint64_t(st.st_dev), uint64_t(st.st_ino), uint64_t(st.st_size),
          int64_t(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec};
}

// The whole file, read once from one descriptor, and that descriptor's stamp.
std::vector<unsigned char> readWhole(const std::string& path, ShardHeader::Stamp& stamp) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw FarmError(path + ": " + std::strerror(errno));
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st;
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) throw FarmError(path + ": not a regular file");
  stamp = stampOf(st);
  std::vector<unsigned char> bytes(size_t(st.st_size));
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::read(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw FarmError(path + ": cut short while it was read (" + (n < 0 ? std::strerror(errno) : "end of file") + ")");
    done += size_t(n);
  }
  return bytes;
}
}  // namespace

ShardHeader readShardHeader(const std::string& path) {
  // The stamp first: a file replaced after it shows as a changed stamp at merge.
  struct stat st;
  const bool stamped = ::stat(path.c_str(), &st) == 0;
  HeaderGuard g;
  parseHeader(path, g);
  ShardHeader h = headerFrom(g.header, path);
  if (stamped) h.stamp = stampOf(st);
  return h;
}

namespace {
// Loads `path`'s pixels and hands every sum word to fn(sum index, word number,
// value) and, with `features`, returns its float channels other than R, G, B there.
template <typename Fn>
ShardHeader forEachSumWord(const std::string& path, Fn&& fn, std::vector<ExrChannel>* features = nullptr,
                           const ShardHeader* checked = nullptr) {
  ShardHeader::Stamp stamp;
  const std::vector<unsigned char> bytes = readWhole(path, stamp);
  HeaderGuard g;
  EXRVersion version;
  if (ParseEXRVersionFromMemory(&version, bytes.data(), bytes.size()) != TINYEXR_SUCCESS)
    throw FarmError(path + ": not an EXR file");
  const char* err = nullptr;
  if (ParseEXRHeaderFromMemory(&g.header, &version, bytes.data(), bytes.size(), &err) != TINYEXR_SUCCESS) {
    const std::string message = err ? err : "unreadable header";
    FreeEXRErrorMessage(err);
    throw FarmError(path + ": " + message);
  }
  g.parsed = true;
  ShardHeader h = headerFrom(g.header, path);
  h.stamp = stamp;
  if (checked && (h.stamp != checked->stamp || !headerMismatch(h, *checked).empty() ||
                  h.samples.begin != checked->samples.begin || h.samples.end != checked->samples.end ||
                  h.frame != checked->frame || h.time != checked->time || h.slice != checked->slice ||
                  h.slices != checked->slices || h.layers != checked->layers))
    throw FarmError(path + " changed after its header was checked (replaced or rewritten during the merge); "
                           "nothing of it was merged: merge again once the shards are complete");
  EXRImage image;
  InitEXRImage(&image);
  if (LoadEXRImageFromMemory(&image, &g.header, bytes.data(), bytes.size(), &err) != TINYEXR_SUCCESS) {
    const std::string message = err ? err : "no detail";
    FreeEXRErrorMessage(err);
    throw FarmError(path + ": the pixel data is damaged or cut short (tinyexr: " + message + ")");
  }
  struct ImageGuard {
    EXRImage& i;
    ~ImageGuard() { FreeEXRImage(&i); }
  } image_guard{image};
  if (uint32_t(image.width) != h.width || uint32_t(image.height) != h.height || !image.images)
    throw FarmError(path + ": pixel data does not match its " + std::to_string(h.width) + "x" +
                    std::to_string(h.height) + " header");
  const size_t pixels = size_t(h.width) * h.height;
  const uint32_t stride = h.sumsPerPixel();
  int found = 0;
  for (int c = 0; c < g.header.num_channels; ++c) {
    const std::string name = g.header.channels[c].name;
    const int type = g.header.pixel_types[c];
    if (name.compare(0, 4, "sum.") != 0) {
      if (features && type == TINYEXR_PIXELTYPE_FLOAT && name != "R" && name != "G" && name != "B") {
        const auto* plane = reinterpret_cast<const float*>(image.images[c]);
        features->push_back({name, std::vector<float>(plane, plane + pixels)});
      }
      continue;
    }
    const size_t dot = name.rfind('.');
    const int sum = sumIndex(name.substr(4, dot - 4));
    const int word = dot + 2 == name.size() ? name[dot + 1] - '0' : -1;
    if (sum < 0 || uint32_t(sum) >= stride || word < 0 || word >= kWords || type != TINYEXR_PIXELTYPE_UINT)
      throw FarmError(path + ": unexpected channel '" + name + "' in " +
                      (h.layers ? "a --layers shard" : "a shard without --layers"));
    const auto* plane = reinterpret_cast<const uint32_t*>(image.images[c]);
    for (size_t p = 0; p < pixels; ++p) fn(p * stride + sum, word, plane[p]);
    ++found;
  }
  if (found != int(stride) * kWords) throw FarmError(path + ": not an sdfc shard (sum channels missing)");
  return h;
}
}  // namespace

ShardImage readShard(const std::string& path) {
  const ShardHeader header = readShardHeader(path);
  std::vector<unsigned __int128> words(size_t(header.width) * header.height * header.sumsPerPixel(), 0);
  ShardImage shard;
  shard.header = forEachSumWord(path, [&](size_t i, int word, uint32_t value) {
    words[i] |= static_cast<unsigned __int128>(value) << (32 * word);
  }, &shard.features);
  shard.sums.assign(words.begin(), words.end());
  return shard;
}

ShardHeader addShard(const std::string& path, std::vector<unsigned __int128>& total,
                     std::vector<ExrChannel>* features, const ShardHeader* checked) {
  return forEachSumWord(path, [&](size_t i, int word, uint32_t value) {
    if (i >= total.size()) throw FarmError(path + ": image larger than the other shards");
    total[i] += static_cast<unsigned __int128>(value) << (32 * word);  // modulo 2^128, exact
  }, features, checked);
}

}  // namespace sdfc::farm
