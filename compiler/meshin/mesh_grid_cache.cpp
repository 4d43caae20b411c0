#include "meshin/mesh_grid_cache.h"

#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>

#include "meshin/mesh_distance.h"
#include "meshin/mesh_shape.h"
#include "spirv/spirv_cache.h"

namespace sdfc {
namespace {

// An entry: this magic, the key's 32 hex digits, the value count and a
// checksum (the key function over the values' bytes), then the values.
constexpr char kGridMagic[8] = {'S', 'D', 'F', 'C', 'G', 'R', 'D', '1'};
constexpr size_t kGridKeyDigits = 32;
constexpr size_t kGridHeaderBytes = sizeof kGridMagic + kGridKeyDigits + 8 + kGridKeyDigits;

std::string checksum(const std::vector<float>& values) {
  return spirvCacheKey(std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(float)),
                       "mesh grid values");
}

}  // namespace

std::string meshGridCacheKey(const MeshDistance& mesh, const MeshGridLayout& l, const std::string& version) {
  const std::vector<glm::dvec3>& corners = mesh.corners();
  char layout[256];
  std::snprintf(layout, sizeof layout, "mesh grid v1; sdfc %s; lo %a %a %a; cell %a; dims %d %d %d; band %a",
                version.c_str(), l.lo.x, l.lo.y, l.lo.z, l.cell, l.dims.x, l.dims.y, l.dims.z, l.band);
  return spirvCacheKey(std::string(reinterpret_cast<const char*>(corners.data()), corners.size() * sizeof(glm::dvec3)),
                       layout);
}

std::string meshGridCachePath(const std::string& key) {
  const std::string dir = sdfcCacheDirectory();
  return dir.empty() || key.size() != kGridKeyDigits ? "" : dir + "/mesh-grid/" + key + ".grid";
}

std::optional<std::vector<float>> loadCachedMeshGrid(const std::string& key, size_t corners) {
  const std::string path = meshGridCachePath(key);
  if (path.empty()) return std::nullopt;
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() != kGridHeaderBytes + corners * sizeof(float)) return std::nullopt;
  if (std::memcmp(bytes.data(), kGridMagic, sizeof kGridMagic) != 0) return std::nullopt;
  if (bytes.compare(sizeof kGridMagic, kGridKeyDigits, key) != 0) return std::nullopt;
  std::uint64_t count = 0;
  std::memcpy(&count, bytes.data() + sizeof kGridMagic + kGridKeyDigits, 8);
  if (count != corners) return std::nullopt;
  std::vector<float> values(corners);
  std::memcpy(values.data(), bytes.data() + kGridHeaderBytes, corners * sizeof(float));
  if (bytes.compare(sizeof kGridMagic + kGridKeyDigits + 8, kGridKeyDigits, checksum(values)) != 0) return std::nullopt;
  return values;
}

void storeCachedMeshGrid(const std::string& key, const std::vector<float>& values) {
  const std::string path = meshGridCachePath(key);
  if (path.empty()) return;
  std::string bytes(kGridMagic, sizeof kGridMagic);
  bytes += key;
  const std::uint64_t count = values.size();
  bytes.append(reinterpret_cast<const char*>(&count), 8);
  bytes += checksum(values);
  bytes.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(float));
  writeCacheFile(path, bytes);
}

// MeshShape's grid through the cache (declared in meshin/mesh_shape.h).
MeshGrid MeshShape::cachedGrid(const std::string& cache_version) const {
  if (cache_version.empty()) return buildMeshGrid(*distance, grid_layout);
  const auto start = std::chrono::steady_clock::now();
  const std::string key = meshGridCacheKey(*distance, grid_layout, cache_version);
  if (std::optional<std::vector<float>> values = loadCachedMeshGrid(key, grid_layout.corners())) {
    MeshGrid g;
    g.values = std::move(*values);
    g.from_cache = true;
    g.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return g;
  }
  MeshGrid g = buildMeshGrid(*distance, grid_layout);
  storeCachedMeshGrid(key, g.values);
  return g;
}

}  // namespace sdfc
