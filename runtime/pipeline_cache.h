// The driver's pipeline cache (VkPipelineCache) on disk, beside the SPIR-V
// cache: one file per kernel and device, under DIR/pipeline/, named by the
// device's pipelineCacheUUID, vendor and device IDs, the driver's version and a
// hash of the kernel's SPIR-V. Off unless a front end enables it (the command
// line does, unless --no-cache). Files are written to a unique temporary and
// renamed; one whose wrapper (magic, length, checksum) or Vulkan header (UUID,
// IDs) does not match is ignored and replaced. Failures are never errors.
#pragma once
#include <vulkan/vulkan.h>

#include <cstdint>
#include <string>
#include <vector>

#include "vulkan_context.h"

namespace sdfc {

// The cache's directory (e.g. $XDG_CACHE_HOME/sdfc); "" turns it off.
void setPipelineCacheDirectory(const std::string& directory);
// A directory is set: the front end asked for caches (the vertex shader's SPIR-V
// is then cached too).
bool pipelineCacheEnabled();

struct PipelineCacheFile {
  VkPipelineCache cache = VK_NULL_HANDLE;  // null when off or not creatable
  std::string path;
  size_t loaded_bytes = 0;  // the initial data given to the driver (0: none or rejected)
};

// A pipeline cache for `spirv` on `context`'s device, with the stored data when valid.
PipelineCacheFile openPipelineCache(const VulkanContext& context, const std::vector<uint32_t>& spirv);
// Writes the cache's data back when it differs from what was loaded, and destroys it.
void closePipelineCache(const VulkanContext& context, PipelineCacheFile& file);

}  // namespace sdfc
