#include "render_pipeline.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <string>
#include <cmath>
#include <string>

#include "pipeline_cache.h"
#include "shader_interface.h"
#include "spirv/glsl_to_spirv.h"
#include "spirv/spirv_cache.h"
#include "vk_check.h"

namespace sdfc {
namespace {

// One triangle covering the viewport: vertices (-1,-1), (3,-1), (-1,3).
constexpr const char* kFullscreenVertexGlsl = R"(#version 450
void main() {
  vec2 p = vec2(float((gl_VertexIndex << 1) & 2), float(gl_VertexIndex & 2));
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
)";

const std::vector<uint32_t>& fullscreenVertexSpirv() {
  static const std::vector<uint32_t> words = [] {
    // Through the SPIR-V cache when caches are on: a run whose kernel is cached
    // then never starts glslang, whose first compile of a stage builds that
    // stage's built-in tables (more than the shader itself costs).
    SpirvResult result =
        pipelineCacheEnabled()
            ? cachedGlslToSpirv(kFullscreenVertexGlsl, ShaderStage::Vertex, "fullscreen.vert", false,
                                true, "runtime")
            : glslToSpirv(kFullscreenVertexGlsl, ShaderStage::Vertex, "fullscreen.vert");
    if (!result.ok()) throw RuntimeError("full-screen vertex shader: " + result.log);
    return result.words;
  }();
  return words;
}

VkShaderModule createShaderModule(VkDevice device, const std::vector<uint32_t>& words) {
  VkShaderModuleCreateInfo info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  info.codeSize = words.size() * sizeof(uint32_t);
  info.pCode = words.data();
  VkShaderModule module = VK_NULL_HANDLE;
  VK_CHECK(vkCreateShaderModule(device, &info, nullptr, &module));
  return module;
}

VkRenderPass createRenderPass(VkDevice device) {
  VkAttachmentDescription attachments[kAttachmentCount];
  VkAttachmentReference refs[kAttachmentCount];
  for (uint32_t i = 0; i < kAttachmentCount; ++i) {
    attachments[i] = {};
    attachments[i].format = kAttachmentFormat;
    attachments[i].samples = VK_SAMPLE_COUNT_1_BIT;
    // Every pixel is written by the full-screen triangle: no need to load or clear.
    attachments[i].loadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    attachments[i].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    attachments[i].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    attachments[i].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    attachments[i].initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    attachments[i].finalLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    refs[i] = {i, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  }
  VkSubpassDescription subpass{};
  subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  subpass.colorAttachmentCount = kAttachmentCount;
  subpass.pColorAttachments = refs;

  // Previous pass's transfer read must finish before we overwrite; our writes
  // must be visible to the following copy.
  VkSubpassDependency deps[2]{};
  deps[0].srcSubpass = VK_SUBPASS_EXTERNAL;
  deps[0].dstSubpass = 0;
  deps[0].srcStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
  deps[0].dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  deps[0].srcAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  deps[0].dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  deps[1].srcSubpass = 0;
  deps[1].dstSubpass = VK_SUBPASS_EXTERNAL;
  deps[1].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  deps[1].dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
  deps[1].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  deps[1].dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;

  VkRenderPassCreateInfo info{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
  info.attachmentCount = kAttachmentCount;
  info.pAttachments = attachments;
  info.subpassCount = 1;
  info.pSubpasses = &subpass;
  info.dependencyCount = 2;
  info.pDependencies = deps;
  VkRenderPass render_pass = VK_NULL_HANDLE;
  VK_CHECK(vkCreateRenderPass(device, &info, nullptr, &render_pass));
  return render_pass;
}

}  // namespace

namespace {

// A host-visible storage buffer holding `data`, with the descriptor set that
// binds it (lavapipe's memory is host memory: no staging copy is needed).
void createSceneBuffer(RenderPipeline& pipeline, const VulkanContext& context,
                       const std::vector<float>& data) {
  VkDevice device = context.device;
  VkDescriptorSetLayoutBinding binding{};
  binding.binding = 0;
  binding.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  binding.descriptorCount = 1;
  binding.stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT;
  VkDescriptorSetLayoutCreateInfo layout{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  layout.bindingCount = 1;
  layout.pBindings = &binding;
  VK_CHECK(vkCreateDescriptorSetLayout(device, &layout, nullptr, &pipeline.set_layout));

  const VkDeviceSize bytes = data.size() * sizeof(float);
  if (bytes > context.properties.limits.maxStorageBufferRange)
    throw RuntimeError("the scene's instance data (" + std::to_string(bytes) +
                       " bytes) exceeds the device's storage buffer range");
  VkBufferCreateInfo buffer{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  buffer.size = bytes;
  buffer.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  buffer.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VK_CHECK(vkCreateBuffer(device, &buffer, nullptr, &pipeline.scene_buffer));
  VkMemoryRequirements reqs;
  vkGetBufferMemoryRequirements(device, pipeline.scene_buffer, &reqs);
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  alloc.allocationSize = reqs.size;
  alloc.memoryTypeIndex = findMemoryType(context, reqs.memoryTypeBits,
                                         VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
                                             VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  VK_CHECK(vkAllocateMemory(device, &alloc, nullptr, &pipeline.scene_memory));
  VK_CHECK(vkBindBufferMemory(device, pipeline.scene_buffer, pipeline.scene_memory, 0));
  void* mapped = nullptr;
  VK_CHECK(vkMapMemory(device, pipeline.scene_memory, 0, bytes, 0, &mapped));
  std::memcpy(mapped, data.data(), bytes);
  vkUnmapMemory(device, pipeline.scene_memory);

  VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1};
  VkDescriptorPoolCreateInfo pool{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pool.maxSets = 1;
  pool.poolSizeCount = 1;
  pool.pPoolSizes = &size;
  VK_CHECK(vkCreateDescriptorPool(device, &pool, nullptr, &pipeline.descriptor_pool));
  VkDescriptorSetAllocateInfo set{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  set.descriptorPool = pipeline.descriptor_pool;
  set.descriptorSetCount = 1;
  set.pSetLayouts = &pipeline.set_layout;
  VK_CHECK(vkAllocateDescriptorSets(device, &set, &pipeline.descriptor_set));
  VkDescriptorBufferInfo info{pipeline.scene_buffer, 0, bytes};
  VkWriteDescriptorSet write{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  write.dstSet = pipeline.descriptor_set;
  write.dstBinding = 0;
  write.descriptorCount = 1;
  write.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  write.pBufferInfo = &info;
  vkUpdateDescriptorSets(device, 1, &write, 0, nullptr);
}

}  // namespace

void createRenderPipeline(RenderPipeline& pipeline, const VulkanContext& context,
                          const std::vector<uint32_t>& frag_spirv, const std::vector<float>& scene_data) {
  pipeline = {};
  if (frag_spirv.empty()) throw RuntimeError("empty fragment SPIR-V");
  VkDevice device = context.device;
  VkShaderModule vert = VK_NULL_HANDLE, frag = VK_NULL_HANDLE;
  try {
    pipeline.render_pass = createRenderPass(device);

    VkPushConstantRange range{VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(gpu::FrameParams)};
    VkPipelineLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    layout_info.pushConstantRangeCount = 1;
    layout_info.pPushConstantRanges = &range;
    if (!scene_data.empty()) {
      createSceneBuffer(pipeline, context, scene_data);
      layout_info.setLayoutCount = 1;
      layout_info.pSetLayouts = &pipeline.set_layout;
    }
    VK_CHECK(vkCreatePipelineLayout(device, &layout_info, nullptr, &pipeline.layout));

    vert = createShaderModule(device, fullscreenVertexSpirv());
    frag = createShaderModule(device, frag_spirv);
    VkPipelineShaderStageCreateInfo stages[2]{};
    stages[0].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
    stages[0].module = vert;
    stages[0].pName = "main";
    stages[1] = stages[0];
    stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
    stages[1].module = frag;
    // The kernel's kDriverCapsLoops (prelude.glsl, constant_id 0): an uncapped
    // driver compiles without the code only a loop cap can reach.
    const VkBool32 caps_loops = context.loop_cap ? VK_TRUE : VK_FALSE;
    const VkSpecializationMapEntry caps_loops_entry{0, 0, sizeof(VkBool32)};
    const VkSpecializationInfo specialization{1, &caps_loops_entry, sizeof(VkBool32), &caps_loops};
    stages[1].pSpecializationInfo = &specialization;

    VkPipelineVertexInputStateCreateInfo vertex_input{
        VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    VkPipelineInputAssemblyStateCreateInfo input_assembly{
        VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
    input_assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    VkPipelineViewportStateCreateInfo viewport{
        VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
    viewport.viewportCount = 1;
    viewport.scissorCount = 1;
    VkPipelineRasterizationStateCreateInfo raster{
        VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
    raster.polygonMode = VK_POLYGON_MODE_FILL;
    raster.cullMode = VK_CULL_MODE_NONE;
    raster.lineWidth = 1.0f;
    VkPipelineMultisampleStateCreateInfo multisample{
        VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
    multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
    VkPipelineColorBlendAttachmentState blend_attachments[kAttachmentCount]{};
    for (auto& b : blend_attachments)
      b.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT |
                         VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
    VkPipelineColorBlendStateCreateInfo blend{
        VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
    blend.attachmentCount = kAttachmentCount;
    blend.pAttachments = blend_attachments;
    const VkDynamicState dynamic_states[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    VkPipelineDynamicStateCreateInfo dynamic{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
    dynamic.dynamicStateCount = 2;
    dynamic.pDynamicStates = dynamic_states;

    VkGraphicsPipelineCreateInfo info{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
    info.stageCount = 2;
    info.pStages = stages;
    info.pVertexInputState = &vertex_input;
    info.pInputAssemblyState = &input_assembly;
    info.pViewportState = &viewport;
    info.pRasterizationState = &raster;
    info.pMultisampleState = &multisample;
    info.pColorBlendState = &blend;
    info.pDynamicState = &dynamic;
    info.layout = pipeline.layout;
    info.renderPass = pipeline.render_pass;
    const auto start = std::chrono::steady_clock::now();
    PipelineCacheFile cache = openPipelineCache(context, frag_spirv);
    const VkResult created =
        vkCreateGraphicsPipelines(device, cache.cache, 1, &info, nullptr, &pipeline.pipeline);
    if (created == VK_SUCCESS) closePipelineCache(context, cache);
    else if (cache.cache) vkDestroyPipelineCache(device, cache.cache, nullptr);
    if (created != VK_SUCCESS) throwVkError(created, "vkCreateGraphicsPipelines", __FILE__, __LINE__);
    pipeline.create_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  } catch (...) {
    if (vert) vkDestroyShaderModule(device, vert, nullptr);
    if (frag) vkDestroyShaderModule(device, frag, nullptr);
    destroyRenderPipeline(pipeline, context);
    throw;
  }
  vkDestroyShaderModule(device, vert, nullptr);
  vkDestroyShaderModule(device, frag, nullptr);
}

namespace {

// One render target attachment (and the warm-up's 1x1 one).
VkImageCreateInfo attachmentImageInfo(uint32_t width, uint32_t height) {
  VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  info.imageType = VK_IMAGE_TYPE_2D;
  info.format = kAttachmentFormat;
  info.extent = {width, height, 1};
  info.mipLevels = 1;
  info.arrayLayers = 1;
  info.samples = VK_SAMPLE_COUNT_1_BIT;
  info.tiling = VK_IMAGE_TILING_OPTIMAL;
  info.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  return info;
}

VkImageViewCreateInfo attachmentViewInfo(VkImage image) {
  VkImageViewCreateInfo view{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  view.image = image;
  view.viewType = VK_IMAGE_VIEW_TYPE_2D;
  view.format = kAttachmentFormat;
  view.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  return view;
}

}  // namespace

void warmAttachmentViews(const VulkanContext& context) {
  VkDevice device = context.device;
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
  const VkImageCreateInfo info = attachmentImageInfo(1, 1);
  // Failures are left to the real target's creation, which reports them.
  if (vkCreateImage(device, &info, nullptr, &image) == VK_SUCCESS) {
    VkMemoryRequirements reqs{};
    vkGetImageMemoryRequirements(device, image, &reqs);
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.allocationSize = reqs.size;
    try {
      alloc.memoryTypeIndex = findMemoryType(context, reqs.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    } catch (...) {
      vkDestroyImage(device, image, nullptr);
      return;
    }
    if (vkAllocateMemory(device, &alloc, nullptr, &memory) == VK_SUCCESS &&
        vkBindImageMemory(device, image, memory, 0) == VK_SUCCESS) {
      const VkImageViewCreateInfo view_info = attachmentViewInfo(image);
      if (vkCreateImageView(device, &view_info, nullptr, &view) == VK_SUCCESS)
        vkDestroyImageView(device, view, nullptr);
    }
    if (memory) vkFreeMemory(device, memory, nullptr);
    vkDestroyImage(device, image, nullptr);
  }
}

void destroyRenderPipeline(RenderPipeline& pipeline, const VulkanContext& context) {
  const auto lock = lockQueue(context);
  if (context.device) vkDeviceWaitIdle(context.device);
  if (pipeline.pipeline) vkDestroyPipeline(context.device, pipeline.pipeline, nullptr);
  if (pipeline.layout) vkDestroyPipelineLayout(context.device, pipeline.layout, nullptr);
  if (pipeline.render_pass) vkDestroyRenderPass(context.device, pipeline.render_pass, nullptr);
  if (pipeline.descriptor_pool) vkDestroyDescriptorPool(context.device, pipeline.descriptor_pool, nullptr);
  if (pipeline.set_layout) vkDestroyDescriptorSetLayout(context.device, pipeline.set_layout, nullptr);
  if (pipeline.scene_buffer) vkDestroyBuffer(context.device, pipeline.scene_buffer, nullptr);
  if (pipeline.scene_memory) vkFreeMemory(context.device, pipeline.scene_memory, nullptr);
  pipeline = {};
}

void createRenderTarget(RenderTarget& target, const VulkanContext& context,
                        const RenderPipeline& pipeline, uint32_t width, uint32_t height,
                        VkCommandPool pool) {
  target = {};
  if (width == 0 || height == 0) throw RuntimeError("render size must be at least 1x1");
  const uint32_t max_dim = context.properties.limits.maxFramebufferWidth;
  if (width > max_dim || height > context.properties.limits.maxFramebufferHeight)
    throw RuntimeError("render size " + std::to_string(width) + "x" + std::to_string(height) +
                       " exceeds the device's framebuffer limit");
  VkDevice device = context.device;
  target.width = width;
  target.height = height;
  try {
    // Images: one allocation for all three (same size and requirements).
    VkMemoryRequirements reqs{};
    for (uint32_t i = 0; i < kAttachmentCount; ++i) {
      const VkImageCreateInfo info = attachmentImageInfo(width, height);
      VK_CHECK(vkCreateImage(device, &info, nullptr, &target.images[i]));
    }
    vkGetImageMemoryRequirements(device, target.images[0], &reqs);
    const VkDeviceSize stride = (reqs.size + reqs.alignment - 1) / reqs.alignment * reqs.alignment;
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.allocationSize = stride * kAttachmentCount;
    alloc.memoryTypeIndex = findMemoryType(context, reqs.memoryTypeBits,
                                           VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    VK_CHECK(vkAllocateMemory(device, &alloc, nullptr, &target.image_memory));
    for (uint32_t i = 0; i < kAttachmentCount; ++i) {
      VK_CHECK(vkBindImageMemory(device, target.images[i], target.image_memory, stride * i));
      const VkImageViewCreateInfo view = attachmentViewInfo(target.images[i]);
      VK_CHECK(vkCreateImageView(device, &view, nullptr, &target.views[i]));
    }
    VkFramebufferCreateInfo fb{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    fb.renderPass = pipeline.render_pass;
    fb.attachmentCount = kAttachmentCount;
    fb.pAttachments = target.views;
    fb.width = width;
    fb.height = height;
    fb.layers = 1;
    VK_CHECK(vkCreateFramebuffer(device, &fb, nullptr, &target.framebuffer));

    // Staging buffer, host-visible; cached memory makes CPU reads much faster.
    VkBufferCreateInfo buffer{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    buffer.size = target.floatsPerImage() * sizeof(float) * kAttachmentCount;
    buffer.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    VK_CHECK(vkCreateBuffer(device, &buffer, nullptr, &target.staging));
    VkMemoryRequirements buffer_reqs{};
    vkGetBufferMemoryRequirements(device, target.staging, &buffer_reqs);
    alloc.allocationSize = buffer_reqs.size;
    alloc.memoryTypeIndex = findMemoryType(context, buffer_reqs.memoryTypeBits,
                                           VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT,
                                           VK_MEMORY_PROPERTY_HOST_CACHED_BIT |
                                               VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    target.staging_coherent = context.memory_properties.memoryTypes[alloc.memoryTypeIndex]
                                  .propertyFlags & VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    VK_CHECK(vkAllocateMemory(device, &alloc, nullptr, &target.staging_memory));
    VK_CHECK(vkBindBufferMemory(device, target.staging, target.staging_memory, 0));
    void* mapped = nullptr;
    VK_CHECK(vkMapMemory(device, target.staging_memory, 0, VK_WHOLE_SIZE, 0, &mapped));
    target.mapped = static_cast<const float*>(mapped);

    target.command_pool = pool ? pool : context.command_pool;
    VkCommandBufferAllocateInfo cb{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    cb.commandPool = target.command_pool;
    cb.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cb.commandBufferCount = 1;
    VK_CHECK(vkAllocateCommandBuffers(device, &cb, &target.command_buffer));
    VkFenceCreateInfo fence{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VK_CHECK(vkCreateFence(device, &fence, nullptr, &target.fence));
  } catch (...) {
    destroyRenderTarget(target, context);
    throw;
  }
}

void destroyRenderTarget(RenderTarget& target, const VulkanContext& context) {
  VkDevice device = context.device;
  if (!device) return;
  const auto lock = lockQueue(context);
  vkDeviceWaitIdle(device);  // a timed-out pass may still be running
  if (target.fence) vkDestroyFence(device, target.fence, nullptr);
  if (target.command_buffer)
    vkFreeCommandBuffers(device, target.command_pool ? target.command_pool : context.command_pool, 1,
                         &target.command_buffer);
  if (target.staging) vkDestroyBuffer(device, target.staging, nullptr);
  if (target.staging_memory) vkFreeMemory(device, target.staging_memory, nullptr);  // unmaps
  if (target.framebuffer) vkDestroyFramebuffer(device, target.framebuffer, nullptr);
  for (uint32_t i = 0; i < kAttachmentCount; ++i) {
    if (target.views[i]) vkDestroyImageView(device, target.views[i], nullptr);
    if (target.images[i]) vkDestroyImage(device, target.images[i], nullptr);
  }
  if (target.image_memory) vkFreeMemory(device, target.image_memory, nullptr);
  target = {};
}

void runPass(const VulkanContext& context, const RenderPipeline& pipeline, RenderTarget& target,
             const void* push_constants, double timeout_seconds, uint32_t rows,
             uint32_t readback) {
  if (rows == 0 || rows > target.height) rows = target.height;
  PassDraw draw;
  draw.rect = {{0, 0}, {target.width, rows}};
  std::memcpy(&draw.params, push_constants, sizeof(gpu::FrameParams));
  runPass(context, pipeline, target, &draw, 1, timeout_seconds, rows, readback);
}

void runPass(const VulkanContext& context, const RenderPipeline& pipeline, RenderTarget& target,
             const PassDraw* draws, size_t draw_count, double timeout_seconds, uint32_t rows,
             uint32_t readback) {
  const auto lock = lockQueue(context);
  if (rows == 0 || rows > target.height) rows = target.height;
  const double clamped = std::fmax(0.0, std::fmin(timeout_seconds, 1.0e9));
  const uint64_t timeout_ns = static_cast<uint64_t>(clamped * 1e9);
  if (target.pending) {
    // A previous pass timed out: its command buffer may still execute.
    const VkResult wait = vkWaitForFences(context.device, 1, &target.fence, VK_TRUE, timeout_ns);
    if (wait == VK_TIMEOUT) throw RuntimeError("the previous render pass is still running");
    if (wait != VK_SUCCESS) throwVkError(wait, "vkWaitForFences", __FILE__, __LINE__);
    target.pending = false;
  }
  VkCommandBuffer cmd = target.command_buffer;
  VK_CHECK(vkResetCommandBuffer(cmd, 0));
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_CHECK(vkBeginCommandBuffer(cmd, &begin));

  VkRenderPassBeginInfo rp{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  rp.renderPass = pipeline.render_pass;
  rp.framebuffer = target.framebuffer;
  rp.renderArea = {{0, 0}, {target.width, rows}};
  vkCmdBeginRenderPass(cmd, &rp, VK_SUBPASS_CONTENTS_INLINE);
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline.pipeline);
  if (pipeline.descriptor_set)
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline.layout, 0, 1,
                            &pipeline.descriptor_set, 0, nullptr);
  const VkViewport viewport{0, 0, float(target.width), float(target.height), 0, 1};
  vkCmdSetViewport(cmd, 0, 1, &viewport);
  for (size_t i = 0; i < draw_count; ++i) {
    const PassDraw& draw = draws[i];
    vkCmdSetScissor(cmd, 0, 1, &draw.rect);
    vkCmdPushConstants(cmd, pipeline.layout, VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                       sizeof(gpu::FrameParams), &draw.params);
    vkCmdDraw(cmd, 3, 1, 0, 0);
  }
  vkCmdEndRenderPass(cmd);

  // The render pass left the images in TRANSFER_SRC_OPTIMAL (with a dependency).
  const VkDeviceSize image_bytes = target.floatsPerImage() * sizeof(float);
  for (uint32_t i = 0; i < kAttachmentCount; ++i) {
    if (!(readback & (1u << i))) continue;
    VkBufferImageCopy region{};
    region.bufferOffset = image_bytes * i;
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {target.width, rows, 1};
    vkCmdCopyImageToBuffer(cmd, target.images[i], VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                           target.staging, 1, &region);
  }
  VkBufferMemoryBarrier to_host{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
  to_host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  to_host.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  to_host.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  to_host.buffer = target.staging;
  to_host.size = VK_WHOLE_SIZE;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 0,
                       nullptr, 1, &to_host, 0, nullptr);
  VK_CHECK(vkEndCommandBuffer(cmd));

  VK_CHECK(vkResetFences(context.device, 1, &target.fence));
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cmd;
  VK_CHECK(vkQueueSubmit(context.queue, 1, &submit, target.fence));
  target.pending = true;

  // Lavapipe has no watchdog: a runaway shader would block forever without our own limit.
  const VkResult wait = vkWaitForFences(context.device, 1, &target.fence, VK_TRUE, timeout_ns);
  if (wait == VK_TIMEOUT)
    throw RuntimeError("render pass did not finish within " + std::to_string(timeout_seconds) +
                       " s (GPU hang or a pass too heavy; lower samples per pass)");
  if (wait != VK_SUCCESS) throwVkError(wait, "vkWaitForFences", __FILE__, __LINE__);
  target.pending = false;

  if (!target.staging_coherent) {
    VkMappedMemoryRange range{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE};
    range.memory = target.staging_memory;
    range.size = VK_WHOLE_SIZE;
    VK_CHECK(vkInvalidateMappedMemoryRanges(context.device, 1, &range));
  }
}

}  // namespace sdfc
