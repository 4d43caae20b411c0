#include "pipeline_cache.h"

#include "spirv/spirv_cache.h"

#include <unistd.h>
#include <sys/stat.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <mutex>

namespace sdfc {
namespace {

std::mutex g_mutex;
std::string g_directory;

constexpr char kMagic[8] = {'S', 'D', 'F', 'C', 'P', 'L', 'C', '1'};
constexpr size_t kWrapperBytes = sizeof kMagic + 16;

std::uint64_t fnv1a(const void* data, size_t size) {
  std::uint64_t h = 1469598103934665603ull;
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < size; ++i) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}

std::uint64_t readU64(const unsigned char* p) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
void appendU64(std::string& out, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

// VkPipelineCacheHeaderVersionOne of this device: the driver's own data starts with it.
bool headerMatches(const VulkanContext& context, const unsigned char* data, size_t size) {
  if (size < 32) return false;
  std::uint32_t fields[4];
  std::memcpy(fields, data, sizeof fields);
  const VkPhysicalDeviceProperties& p = context.properties;
  return fields[0] >= 32 && fields[1] == VK_PIPELINE_CACHE_HEADER_VERSION_ONE &&
         fields[2] == p.vendorID && fields[3] == p.deviceID &&
         std::memcmp(data + 16, p.pipelineCacheUUID, VK_UUID_SIZE) == 0;
}

}  // namespace

void setPipelineCacheDirectory(const std::string& directory) {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_directory = directory;
}

bool pipelineCacheEnabled() {
  std::lock_guard<std::mutex> lock(g_mutex);
  return !g_directory.empty();
}

PipelineCacheFile openPipelineCache(const VulkanContext& context, const std::vector<uint32_t>& spirv) {
  PipelineCacheFile file;
  std::string directory;
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    directory = g_directory;
  }
  if (directory.empty() || !context.device) return file;
  const VkPhysicalDeviceProperties& p = context.properties;
  char name[160];
  std::string uuid;
  for (uint8_t b : p.pipelineCacheUUID) {
    char hex[3];
    std::snprintf(hex, sizeof hex, "%02x", b);
    uuid += hex;
  }
  std::snprintf(name, sizeof name, "%s-%08x-%08x-%08x-%016llx.bin", uuid.c_str(), p.vendorID,
                p.deviceID, p.driverVersion,
                static_cast<unsigned long long>(fnv1a(spirv.data(), spirv.size() * 4)));
  file.path = directory + "/pipeline/" + name;

  std::string stored;
  {
    std::ifstream in(file.path, std::ios::binary);
    if (in) stored.assign((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  }
  const auto* bytes = reinterpret_cast<const unsigned char*>(stored.data());
  const unsigned char* data = nullptr;
  size_t size = 0;
  if (stored.size() > kWrapperBytes && std::memcmp(bytes, kMagic, sizeof kMagic) == 0) {
    size = readU64(bytes + sizeof kMagic);
    data = bytes + kWrapperBytes;
    if (size != stored.size() - kWrapperBytes || fnv1a(data, size) != readU64(bytes + sizeof kMagic + 8) ||
        !headerMatches(context, data, size)) {
      data = nullptr;
      size = 0;
    }
  }
  VkPipelineCacheCreateInfo info{VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO};
  info.initialDataSize = size;
  info.pInitialData = data;
  if (vkCreatePipelineCache(context.device, &info, nullptr, &file.cache) != VK_SUCCESS) {
    file.cache = VK_NULL_HANDLE;
    return file;
  }
  file.loaded_bytes = size;
  return file;
}

void closePipelineCache(const VulkanContext& context, PipelineCacheFile& file) {
  if (!file.cache) return;
  size_t size = 0;
  if (vkGetPipelineCacheData(context.device, file.cache, &size, nullptr) == VK_SUCCESS && size > 0 &&
      size != file.loaded_bytes) {
    std::string data(size, '\0');
    if (vkGetPipelineCacheData(context.device, file.cache, &size, data.data()) == VK_SUCCESS) {
      data.resize(size);
      std::string bytes(kMagic, sizeof kMagic);
      appendU64(bytes, data.size());
      appendU64(bytes, fnv1a(data.data(), data.size()));
      bytes += data;
      writeCacheFile(file.path, bytes);
    }
  }
  vkDestroyPipelineCache(context.device, file.cache, nullptr);
  file.cache = VK_NULL_HANDLE;
}

}  // namespace sdfc
