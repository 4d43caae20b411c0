// The PNG writer's tone map and sRGB bytes (image_io.h: toSrgb8) as a compute pass
// on the device, for `sdfc view`: a frame's linear RGBA floats become 8-bit pixels
// in the swapchain image's byte order, enlarged by an integer factor, and the bytes
// never pass through the CPU. The same operations in the same order on the same
// floats (NoContraction, srgb8Fast's threshold table), so the same bytes as toSrgb8.
#pragma once
#include <vulkan/vulkan.h>

#include <cstdint>

#include "image_io.h"
#include "vulkan_context.h"

namespace sdfc {

// Where the source pixels go in the output (the swapchain image).
struct DisplayLayout {
  uint32_t width = 0, height = 0;  // the source floats
  uint32_t scale = 1;              // nearest-neighbour enlargement
  uint32_t out_width = 0, out_height = 0;          // output pixels, row-major
  uint32_t covered_width = 0, covered_height = 0;  // outside this: black (0 bytes)
  bool bgr = false;  // output bytes B, G, R, 255 instead of R, G, B, 255
};

class DisplayPass {
 public:
  explicit DisplayPass(const VulkanContext& context);
  ~DisplayPass();
  DisplayPass(const DisplayPass&) = delete;
  DisplayPass& operator=(const DisplayPass&) = delete;

  // Host-visible storage for width x height RGBA floats, row-major, top row first:
  // the caller writes the frame here. Its contents stay until the next call; the
  // caller must know no submitted record() still reads it (a fence).
  float* input(uint32_t width, uint32_t height);
  // Records the tone map of the input into `output` (out_width * out_height words,
  // a storage buffer), then a barrier that makes them visible to transfer reads.
  // No submitted record() may still be pending (the descriptors are written here);
  // `output` may change between calls (a new swapchain).
  void record(VkCommandBuffer cmd, const ToneMap& tone, const DisplayLayout& layout, VkBuffer output,
              VkDeviceSize output_size);

 private:
  void bind(VkBuffer output, VkDeviceSize output_size);

  const VulkanContext& context_;
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipelines_[3]{};  // by curve (0 linear, 1 aces, 2 neutral), made on first use
  VkPipeline pipelineFor(uint32_t curve);
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  VkDescriptorSet set_ = VK_NULL_HANDLE;
  struct HostBuffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    void* mapped = nullptr;
    VkDeviceSize size = 0;
    bool coherent = false;
  };
  HostBuffer input_, thresholds_;
  uint32_t input_width_ = 0, input_height_ = 0;

  HostBuffer createHostBuffer(VkDeviceSize size);
  void destroyHostBuffer(HostBuffer& b);
};

}  // namespace sdfc
