#include "display_pass.h"

#include <algorithm>
#include <array>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

#include "pipeline_cache.h"
#include "spirv/glsl_to_spirv.h"
#include "spirv/spirv_cache.h"
#include "vk_check.h"

namespace sdfc {
namespace {

struct PushConstants {
  uint32_t width, height, scale, out_width, out_height, covered_width, covered_height;
  uint32_t bgr;
  float exposure_scale;
};

constexpr uint32_t kGroup = 128;  // lavapipe runs a work group as one task: few, large ones

// A float constant written by its bits: glslang's parse of a decimal need not
// round as the C++ compiler's does.
std::string bits(float value) {
  uint32_t u;
  std::memcpy(&u, &value, sizeof u);
  char text[40];
  std::snprintf(text, sizeof text, "uintBitsToFloat(0x%08" PRIx32 "u)", u);
  return text;
}

// image_io.cpp's toneMapScaled, operation for operation (the constants are its
// expressions, evaluated by the C++ compiler), `precise` so that no multiply and
// add fuse; then srgb8Fast's byte. DisplayPass tests hold it to toSrgb8.
std::string displayGlsl() {
  constexpr float kStart = 0.8f - 0.04f, kDesaturation = 0.15f;
  constexpr float d = 1.0f - kStart;
  return R"(#version 450
layout(local_size_x = 128) in;
layout(std430, set = 0, binding = 0) readonly buffer Linear { vec4 rgba[]; } src;
layout(std430, set = 0, binding = 1) writeonly buffer Pixels { uint words[]; } dst;
layout(std430, set = 0, binding = 2) readonly buffer Thresholds { float t[256]; } table;
// The curve is a specialisation constant: lavapipe runs both sides of a branch,
// so the curves not in use are compiled out rather than masked.
layout(constant_id = 0) const uint kCurve = 2u;
layout(push_constant) uniform Params {
  uint width, height, scale, out_width, out_height, covered_width, covered_height;
  uint bgr;
  float exposure_scale;
} p;

#define kStart )" + bits(kStart) + R"(
#define kD )" + bits(d) + R"(
#define kD2 )" + bits(d * d) + R"(
#define kDesaturation )" + bits(kDesaturation) + R"(

vec3 toneMap(vec3 linear) {
  precise vec3 x;
  for (int c = 0; c < 3; ++c) {
    x[c] = linear[c] * p.exposure_scale;
    if (!(x[c] > 0.0)) x[c] = 0.0;  // also NaN
  }
  if (kCurve == 2u) {  // Khronos PBR Neutral
    precise float lo = min(min(x[0], x[1]), x[2]);
    precise float offset = lo < )" + bits(0.08f) + R"( ? lo - )" + bits(6.25f) + R"( * lo * lo : )" +
         bits(0.04f) + R"(;
    for (int c = 0; c < 3; ++c) x[c] = x[c] - offset;
    precise float peak = max(max(x[0], x[1]), x[2]);
    if (peak >= kStart) {
      precise float new_peak = 1.0 - kD2 / (peak + kD - kStart);
      precise float g = 1.0 - 1.0 / (kDesaturation * (peak - new_peak) + 1.0);
      for (int c = 0; c < 3; ++c) x[c] = x[c] * (new_peak / peak) * (1.0 - g) + new_peak * g;
    }
    // std::clamp and std::min as written (GLSL's return the other operand for NaN).
    for (int c = 0; c < 3; ++c) x[c] = x[c] < 0.0 ? 0.0 : 1.0 < x[c] ? 1.0 : x[c];
    return x;
  }
  precise vec3 o;
  for (int c = 0; c < 3; ++c) {
    precise float v = x[c];
    if (v > 0.0 && kCurve == 1u)
      v = (v * ()" + bits(2.51f) + R"( * v + )" + bits(0.03f) + R"()) / (v * ()" + bits(2.43f) +
         R"( * v + )" + bits(0.59f) + R"() + )" + bits(0.14f) + R"();  // Narkowicz 2015
    o[c] = 1.0 < v ? 1.0 : v;  // an infinite input is NaN here, black as on the CPU
  }
  return o;
}

// srgb8Fast's byte: the largest k with t[k] <= v. The sRGB curve's own estimate,
// biased down by 0.01 of a byte, is the byte or the one below (the device's pow
// is within a few ulps of the CPU's, 1e-3 of a byte), and one read of the table
// settles which: lavapipe's buffer reads cost more than the arithmetic.
uint srgb8(float v) {
  float e = v <= 0.0031308 ? 12.92 * v : 1.055 * pow(max(v, 0.0), 1.0 / 2.4) - 0.055;
  uint k = uint(max(clamp(e, 0.0, 1.0) * 255.0 + 0.49, 0.0));
  return k < 255u && table.t[k + 1u] <= v ? k + 1u : k;
}

void main() {
  uint x = gl_GlobalInvocationID.x, y = gl_GlobalInvocationID.y;
  if (x >= p.out_width || y >= p.out_height) return;
  uint word = 0u;
  if (x < p.covered_width && y < p.covered_height) {
    uint sx = min(x / p.scale, p.width - 1u), sy = min(y / p.scale, p.height - 1u);
    vec3 m = toneMap(src.rgba[sy * p.width + sx].rgb);
    uint r = srgb8(m[0]), g = srgb8(m[1]), b = srgb8(m[2]);
    word = p.bgr != 0u ? (b | (g << 8) | (r << 16) | 0xFF000000u) : (r | (g << 8) | (b << 16) | 0xFF000000u);
  }
  dst.words[y * p.out_width + x] = word;
}
)";
}

const std::vector<uint32_t>& displaySpirv() {
  static const std::vector<uint32_t> words = [] {
    const std::string source = displayGlsl();
    // Through the SPIR-V cache as the full-screen vertex shader (render_pipeline.cpp).
    SpirvResult result = pipelineCacheEnabled()
                             ? cachedGlslToSpirv(source, ShaderStage::Compute, "display.comp", false, true,
                                                 "runtime")
                             : glslToSpirv(source, ShaderStage::Compute, "display.comp");
    if (!result.ok()) throw RuntimeError("display compute shader: " + result.log);
    return result.words;
  }();
  return words;
}

}  // namespace

DisplayPass::DisplayPass(const VulkanContext& context) : context_(context) {
  VkDevice device = context.device;
  VkDescriptorSetLayoutBinding bindings[3]{};
  for (uint32_t i = 0; i < 3; ++i) {
    bindings[i].binding = i;
    bindings[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    bindings[i].descriptorCount = 1;
    bindings[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
  }
  VkDescriptorSetLayoutCreateInfo set_info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  set_info.bindingCount = 3;
  set_info.pBindings = bindings;
  VK_CHECK(vkCreateDescriptorSetLayout(device, &set_info, nullptr, &set_layout_));
  VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(PushConstants)};
  VkPipelineLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layout_info.setLayoutCount = 1;
  layout_info.pSetLayouts = &set_layout_;
  layout_info.pushConstantRangeCount = 1;
  layout_info.pPushConstantRanges = &range;
  VK_CHECK(vkCreatePipelineLayout(device, &layout_info, nullptr, &layout_));
  pipelineFor(2);  // the default curve's now (the first frame then pays none)

  VkDescriptorPoolSize pool_size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 3};
  VkDescriptorPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pool_info.maxSets = 1;
  pool_info.poolSizeCount = 1;
  pool_info.pPoolSizes = &pool_size;
  VK_CHECK(vkCreateDescriptorPool(device, &pool_info, nullptr, &pool_));
  VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  alloc.descriptorPool = pool_;
  alloc.descriptorSetCount = 1;
  alloc.pSetLayouts = &set_layout_;
  VK_CHECK(vkAllocateDescriptorSets(device, &alloc, &set_));

  const std::array<float, 256>& table = srgb8Thresholds();
  thresholds_ = createHostBuffer(sizeof(float) * table.size());
  std::memcpy(thresholds_.mapped, table.data(), sizeof(float) * table.size());
  if (!thresholds_.coherent) {
    VkMappedMemoryRange flush{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE};
    flush.memory = thresholds_.memory;
    flush.size = VK_WHOLE_SIZE;
    VK_CHECK(vkFlushMappedMemoryRanges(device, 1, &flush));
  }
}

VkPipeline DisplayPass::pipelineFor(uint32_t curve) {
  VkPipeline& pipeline = pipelines_[curve];
  if (pipeline) return pipeline;
  VkDevice device = context_.device;
  const std::vector<uint32_t>& words = displaySpirv();
  VkShaderModuleCreateInfo module_info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  module_info.codeSize = words.size() * sizeof(uint32_t);
  module_info.pCode = words.data();
  VkShaderModule module = VK_NULL_HANDLE;
  VK_CHECK(vkCreateShaderModule(device, &module_info, nullptr, &module));
  VkSpecializationMapEntry entry{0, 0, sizeof(uint32_t)};
  VkSpecializationInfo specialization{1, &entry, sizeof(uint32_t), &curve};
  VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  info.stage.module = module;
  info.stage.pName = "main";
  info.stage.pSpecializationInfo = &specialization;
  info.layout = layout_;
  const VkResult r = vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline);
  vkDestroyShaderModule(device, module, nullptr);
  if (r != VK_SUCCESS) throwVkError(r, "vkCreateComputePipelines", __FILE__, __LINE__);
  return pipeline;
}

DisplayPass::~DisplayPass() {
  VkDevice device = context_.device;
  destroyHostBuffer(input_);
  destroyHostBuffer(thresholds_);
  if (pool_) vkDestroyDescriptorPool(device, pool_, nullptr);
  for (VkPipeline pipeline : pipelines_)
    if (pipeline) vkDestroyPipeline(device, pipeline, nullptr);
  if (layout_) vkDestroyPipelineLayout(device, layout_, nullptr);
  if (set_layout_) vkDestroyDescriptorSetLayout(device, set_layout_, nullptr);
}

DisplayPass::HostBuffer DisplayPass::createHostBuffer(VkDeviceSize size) {
  VkDevice device = context_.device;
  HostBuffer b;
  b.size = size;
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = size;
  info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  VK_CHECK(vkCreateBuffer(device, &info, nullptr, &b.buffer));
  VkMemoryRequirements reqs{};
  vkGetBufferMemoryRequirements(device, b.buffer, &reqs);
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  alloc.allocationSize = reqs.size;
  // Written by the CPU each frame and read once by the pass: host memory (on
  // lavapipe all memory is).
  alloc.memoryTypeIndex = findMemoryType(context_, reqs.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT,
                                         VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  b.coherent = context_.memory_properties.memoryTypes[alloc.memoryTypeIndex].propertyFlags &
               VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  VK_CHECK(vkAllocateMemory(device, &alloc, nullptr, &b.memory));
  VK_CHECK(vkBindBufferMemory(device, b.buffer, b.memory, 0));
  VK_CHECK(vkMapMemory(device, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped));
  return b;
}

void DisplayPass::destroyHostBuffer(HostBuffer& b) {
  if (b.buffer) vkDestroyBuffer(context_.device, b.buffer, nullptr);
  if (b.memory) vkFreeMemory(context_.device, b.memory, nullptr);
  b = HostBuffer{};
}

float* DisplayPass::input(uint32_t width, uint32_t height) {
  const VkDeviceSize size = VkDeviceSize(std::max(width, 1u)) * std::max(height, 1u) * 4 * sizeof(float);
  if (size > input_.size) {
    destroyHostBuffer(input_);
    input_ = createHostBuffer(size);
  }
  input_width_ = width;
  input_height_ = height;
  return static_cast<float*>(input_.mapped);
}

void DisplayPass::bind(VkBuffer output, VkDeviceSize output_size) {
  // Written every frame, not only when a handle changes: a new swapchain's staging
  // may reuse a destroyed buffer's handle. Nothing pending reads the set (record's contract).
  VkDescriptorBufferInfo buffers[3] = {{input_.buffer, 0, input_.size},
                                       {output, 0, output_size},
                                       {thresholds_.buffer, 0, thresholds_.size}};
  VkWriteDescriptorSet writes[3]{};
  for (uint32_t i = 0; i < 3; ++i) {
    writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    writes[i].dstSet = set_;
    writes[i].dstBinding = i;
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[i].pBufferInfo = &buffers[i];
  }
  vkUpdateDescriptorSets(context_.device, 3, writes, 0, nullptr);
}

void DisplayPass::record(VkCommandBuffer cmd, const ToneMap& tone, const DisplayLayout& layout, VkBuffer output,
                         VkDeviceSize output_size) {
  if (!input_.buffer) input(layout.width, layout.height);
  if (!input_.coherent) {
    VkMappedMemoryRange flush{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE};
    flush.memory = input_.memory;
    flush.size = VK_WHOLE_SIZE;
    VK_CHECK(vkFlushMappedMemoryRanges(context_.device, 1, &flush));
  }
  bind(output, output_size);
  // The curve picks the pipeline (its specialisation constant: 0 linear, 1 aces, 2 neutral).
  const uint32_t curve = tone.curve == ToneCurve::Clamp ? 0u : tone.curve == ToneCurve::AcesFit ? 1u : 2u;
  PushConstants pc{};
  pc.width = std::max(1u, layout.width);
  pc.height = std::max(1u, layout.height);
  pc.scale = std::max(1u, layout.scale);
  pc.out_width = layout.out_width;
  pc.out_height = layout.out_height;
  pc.covered_width = layout.covered_width;
  pc.covered_height = layout.covered_height;
  pc.bgr = layout.bgr ? 1u : 0u;
  pc.exposure_scale = std::exp2(tone.exposure_stops);  // as toSrgb8: taken once
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipelineFor(curve));
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, 0, 1, &set_, 0, nullptr);
  vkCmdPushConstants(cmd, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof pc, &pc);
  vkCmdDispatch(cmd, (layout.out_width + kGroup - 1) / kGroup, layout.out_height, 1);
  VkBufferMemoryBarrier barrier{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
  barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  barrier.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_HOST_READ_BIT;
  barrier.srcQueueFamilyIndex = barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.buffer = output;
  barrier.size = VK_WHOLE_SIZE;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                       VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_HOST_BIT, 0, 0, nullptr, 1, &barrier,
                       0, nullptr);
}

}  // namespace sdfc
