// The graphics pipeline that runs a scene's fragment shader once per pixel,
// and the offscreen target it renders into (three RGBA32F attachments read back
// through one host-visible staging buffer). Plain structs + create/destroy.
#pragma once
#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

#include "shader_interface.h"
#include "vulkan_context.h"

namespace sdfc {

constexpr uint32_t kAttachmentCount = 3;  // locations 0..2, see shader_interface.h
// Which attachments a pass copies to the staging buffer (runPass's `readback`).
constexpr uint32_t kReadColor = 1u << 0, kReadNormalDepth = 1u << 1, kReadAlbedoSteps = 1u << 2;
constexpr uint32_t kReadAll = kReadColor | kReadNormalDepth | kReadAlbedoSteps;
constexpr VkFormat kAttachmentFormat = VK_FORMAT_R32G32B32A32_SFLOAT;

struct RenderPipeline {
  VkRenderPass render_pass = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  double create_seconds = 0;  // vkCreateGraphicsPipelines alone (LLVM compile on lavapipe)
  // The scene's storage buffer (instance hierarchies), set 0 binding 0; absent
  // when the scene has none.
  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
  VkDescriptorPool descriptor_pool = VK_NULL_HANDLE;
  VkDescriptorSet descriptor_set = VK_NULL_HANDLE;
  VkBuffer scene_buffer = VK_NULL_HANDLE;
  VkDeviceMemory scene_memory = VK_NULL_HANDLE;
};

// Full-screen triangle vertex shader (compiled in process) + `frag_spirv`, push
// constants = gpu::FrameParams for the fragment stage, dynamic viewport/scissor.
// `scene_data` (vec4s), when not empty, is copied into a storage buffer bound
// at set 0, binding 0 for the fragment stage.
void createRenderPipeline(RenderPipeline& pipeline, const VulkanContext& context,
                          const std::vector<uint32_t>& frag_spirv,
                          const std::vector<float>& scene_data = {});
void destroyRenderPipeline(RenderPipeline& pipeline, const VulkanContext& context);

// Creates and destroys one 1x1 attachment image and its view. Mesa 24+'s lavapipe
// JIT-compiles its texture functions for a format at the first view of it (tens
// of ms, once per device): run beside createRenderPipeline, that compile overlaps
// the pipeline's instead of delaying the first draw. Errors are ignored (the real
// target reports them).
void warmAttachmentViews(const VulkanContext& context);

struct RenderTarget {
  uint32_t width = 0, height = 0;
  VkImage images[kAttachmentCount]{};
  VkImageView views[kAttachmentCount]{};
  VkDeviceMemory image_memory = VK_NULL_HANDLE;
  VkFramebuffer framebuffer = VK_NULL_HANDLE;
  VkBuffer staging = VK_NULL_HANDLE;
  VkDeviceMemory staging_memory = VK_NULL_HANDLE;
  bool staging_coherent = false;
  const float* mapped = nullptr;  // kAttachmentCount images of width*height*4 floats, in order
  VkCommandPool command_pool = VK_NULL_HANDLE;  // where command_buffer came from
  VkCommandBuffer command_buffer = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  bool pending = false;  // submitted, fence not yet seen signalled (after a timeout)

  size_t floatsPerImage() const { return size_t(width) * height * 4; }
};

// `pool`: the command pool of the thread that will draw into the target (a pool
// is externally synchronised); null: the context's.
void createRenderTarget(RenderTarget& target, const VulkanContext& context,
                        const RenderPipeline& pipeline, uint32_t width, uint32_t height,
                        VkCommandPool pool = VK_NULL_HANDLE);
void destroyRenderTarget(RenderTarget& target, const VulkanContext& context);

// Records, submits and waits for one draw with `push_constants` (sizeof(gpu::FrameParams)
// bytes) over the target's top `rows` rows (0 = all), followed by the copy of the
// attachments in `readback` (kRead* bits) to the staging buffer, each packed as width x rows at its usual
// offset (attachment i at mapped + i * floatsPerImage()). Throws RuntimeError when the fence
// is not signalled within `timeout_seconds`; after that the device may still be busy,
// so destroy functions wait for idle first.
void runPass(const VulkanContext& context, const RenderPipeline& pipeline, RenderTarget& target,
             const void* push_constants, double timeout_seconds, uint32_t rows = 0,
             uint32_t readback = kReadAll);

// One draw of a multi-draw pass: its own push constants over `rect` (target pixels).
struct PassDraw {
  VkRect2D rect{};
  gpu::FrameParams params{};
};

// runPass with several draws in one submission, each scissored to its rect (adaptive
// sampling: per-block sample counts without a kernel change). Pixels no rect covers
// are undefined in the readback.
void runPass(const VulkanContext& context, const RenderPipeline& pipeline, RenderTarget& target,
             const PassDraw* draws, size_t draw_count, double timeout_seconds, uint32_t rows = 0,
             uint32_t readback = kReadAll);

}  // namespace sdfc
