#include "spirv/spirv_cache.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <glslang/build_info.h>
#include <spirv-tools/libspirv.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace sdfc {
namespace {

// An entry: this magic, the key's 32 hex digits, the word count and an FNV-1a
// checksum of the words (both little-endian u64), then the words.
constexpr char kMagic[8] = {'S', 'D', 'F', 'C', 'S', 'P', 'V', '1'};
constexpr size_t kKeyDigits = 32;
constexpr size_t kHeaderBytes = sizeof kMagic + kKeyDigits + 16;
constexpr std::uint32_t kSpirvMagic = 0x07230203;

std::uint64_t fnv1a(const void* data, size_t size, std::uint64_t h = 1469598103934665603ull) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < size; ++i) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}

// A second, unrelated 64-bit hash (splitmix64's finaliser over 8-byte blocks),
// so the key's 128 bits are two independent halves.
std::uint64_t mix64(std::uint64_t x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ull;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}
std::uint64_t blockHash(const std::string& s) {
  std::uint64_t h = 0x9e3779b97f4a7c15ull ^ s.size();
  for (size_t i = 0; i < s.size(); i += 8) {
    std::uint64_t block = 0;
    std::memcpy(&block, s.data() + i, std::min<size_t>(8, s.size() - i));
    h = mix64(h ^ block) + 0x9e3779b97f4a7c15ull;
  }
  return mix64(h);
}

std::uint64_t readU64(const unsigned char* p) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
void appendU64(std::string& out, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

// glslang's and SPIRV-Tools' versions: a new library may emit other words.
std::string toolVersions() {
  return "glslang " + std::to_string(GLSLANG_VERSION_MAJOR) + "." +
         std::to_string(GLSLANG_VERSION_MINOR) + "." + std::to_string(GLSLANG_VERSION_PATCH) +
         GLSLANG_VERSION_FLAVOR + "; " + spvSoftwareVersionDetailsString();
}

}  // namespace

std::string sdfcCacheDirectory() {
  const char* xdg = std::getenv("XDG_CACHE_HOME");
  // The XDG base directory rules: a relative value is ignored.
  if (xdg && xdg[0] == '/') return std::string(xdg) + "/sdfc";
  const char* home = std::getenv("HOME");
  if (home && home[0]) return std::string(home) + "/.cache/sdfc";
  return "";
}

std::string spirvCacheKey(const std::string& glsl, const std::string& options) {
  std::string material = options;
  material += '\n';
  material += toolVersions();
  material += '\n';
  material += glsl;
  char hex[kKeyDigits + 1];
  std::snprintf(hex, sizeof hex, "%016llx%016llx",
                static_cast<unsigned long long>(fnv1a(material.data(), material.size())),
                static_cast<unsigned long long>(blockHash(material)));
  return hex;
}

std::string spirvCachePath(const std::string& key) {
  const std::string dir = sdfcCacheDirectory();
  return dir.empty() ? "" : dir + "/spirv/" + key + ".spv";
}

std::optional<std::vector<std::uint32_t>> loadCachedSpirv(const std::string& key) {
  const std::string path = spirvCachePath(key);
  if (path.empty() || key.size() != kKeyDigits) return std::nullopt;
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() < kHeaderBytes) return std::nullopt;
  const auto* p = reinterpret_cast<const unsigned char*>(bytes.data());
  if (std::memcmp(p, kMagic, sizeof kMagic) != 0) return std::nullopt;
  if (bytes.compare(sizeof kMagic, kKeyDigits, key) != 0) return std::nullopt;
  const std::uint64_t count = readU64(p + sizeof kMagic + kKeyDigits);
  const std::uint64_t checksum = readU64(p + sizeof kMagic + kKeyDigits + 8);
  if (count < 5 || count != (bytes.size() - kHeaderBytes) / 4 || (bytes.size() - kHeaderBytes) % 4)
    return std::nullopt;
  std::vector<std::uint32_t> words(count);
  std::memcpy(words.data(), p + kHeaderBytes, count * 4);
  if (words[0] != kSpirvMagic || fnv1a(words.data(), count * 4) != checksum) return std::nullopt;
  return words;
}

void writeCacheFile(const std::string& path, const std::string& bytes) {
  std::error_code ec;
  std::filesystem::create_directories(std::filesystem::path(path).parent_path(), ec);
  if (ec) return;
  // A unique temporary beside the entry, renamed over it: a reader sees the old
  // entry, the new one or none, never part of one.
  std::string temp = path + ".XXXXXX";
  const int fd = mkstemp(temp.data());
  if (fd < 0) return;
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    done += size_t(n);
  }
  fchmod(fd, 0644);
  const bool ok = ::close(fd) == 0 && done == bytes.size();
  if (!ok || std::rename(temp.c_str(), path.c_str()) != 0) ::unlink(temp.c_str());
}

void storeCachedSpirv(const std::string& key, const std::vector<std::uint32_t>& words) {
  const std::string path = spirvCachePath(key);
  if (path.empty() || key.size() != kKeyDigits || words.empty()) return;
  std::string bytes(kMagic, sizeof kMagic);
  bytes += key;
  appendU64(bytes, words.size());
  appendU64(bytes, fnv1a(words.data(), words.size() * 4));
  bytes.append(reinterpret_cast<const char*>(words.data()), words.size() * 4);
  writeCacheFile(path, bytes);
}

SpirvResult cachedGlslToSpirv(const std::string& source, ShaderStage stage, const std::string& name,
                              bool optimize, bool validate, const std::string& version, bool* hit) {
  const std::string options = "sdfc " + version + "; stage " +
                              std::to_string(static_cast<int>(stage)) + "; optimize " +
                              (optimize ? "1" : "0");
  const std::string key = spirvCacheKey(source, options);
  if (hit) *hit = false;
  const auto start = std::chrono::steady_clock::now();
  if (std::optional<std::vector<std::uint32_t>> words = loadCachedSpirv(key)) {
    SpirvResult result;
    result.words = std::move(*words);
    result.from_cache = true;
    result.cache_key = key;
    result.compile_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (hit) *hit = true;
    return result;
  }
  SpirvResult result = glslToSpirv(source, stage, name, optimize, validate);
  result.cache_key = key;
  // Only validated words are stored: a hit skips the validator.
  if (result.ok() && validate) storeCachedSpirv(key, result.words);
  return result;
}

}  // namespace sdfc
