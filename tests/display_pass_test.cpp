// The view's tone map on the device (runtime/display_pass.h) gives the PNG
// writer's bytes (toSrgb8) for every curve and exposure, on values that cross
// each sRGB byte's threshold, the neutral curve's shoulder and ACES's range.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "display_pass.h"
#include "image_io.h"
#include "vk_check.h"
#include "vulkan_context.h"

namespace sdfc {
namespace {

struct Output {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  const uint32_t* words = nullptr;
};

Output createOutput(const VulkanContext& context, VkDeviceSize size) {
  Output out;
  VkBufferCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  info.size = size;
  info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  VK_CHECK(vkCreateBuffer(context.device, &info, nullptr, &out.buffer));
  VkMemoryRequirements reqs{};
  vkGetBufferMemoryRequirements(context.device, out.buffer, &reqs);
  VkMemoryAllocateInfo alloc{};
  alloc.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  alloc.allocationSize = reqs.size;
  alloc.memoryTypeIndex = findMemoryType(context, reqs.memoryTypeBits,
                                         VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  VK_CHECK(vkAllocateMemory(context.device, &alloc, nullptr, &out.memory));
  VK_CHECK(vkBindBufferMemory(context.device, out.buffer, out.memory, 0));
  void* mapped = nullptr;
  VK_CHECK(vkMapMemory(context.device, out.memory, 0, VK_WHOLE_SIZE, 0, &mapped));
  out.words = static_cast<const uint32_t*>(mapped);
  return out;
}

// Runs the pass over `image` (scale 1, the whole output covered); RGB bytes.
std::vector<uint8_t> runOnDevice(const VulkanContext& context, DisplayPass& pass, const Output& out,
                                 const FloatImage& image, const ToneMap& tone, bool bgr) {
  std::memcpy(pass.input(image.width, image.height), image.rgba.data(), image.rgba.size() * sizeof(float));
  DisplayLayout layout;
  layout.width = layout.out_width = layout.covered_width = image.width;
  layout.height = layout.out_height = layout.covered_height = image.height;
  layout.bgr = bgr;
  VkCommandBufferAllocateInfo cb{};
  cb.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  cb.commandPool = context.command_pool;
  cb.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cb.commandBufferCount = 1;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VK_CHECK(vkAllocateCommandBuffers(context.device, &cb, &cmd));
  VkCommandBufferBeginInfo begin{};
  begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_CHECK(vkBeginCommandBuffer(cmd, &begin));
  pass.record(cmd, tone, layout, out.buffer, VkDeviceSize(image.pixelCount()) * 4);
  VK_CHECK(vkEndCommandBuffer(cmd));
  VkSubmitInfo submit{};
  submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cmd;
  VK_CHECK(vkQueueSubmit(context.queue, 1, &submit, VK_NULL_HANDLE));
  VK_CHECK(vkQueueWaitIdle(context.queue));
  vkFreeCommandBuffers(context.device, context.command_pool, 1, &cmd);
  std::vector<uint8_t> rgb(image.pixelCount() * 3);
  for (size_t i = 0; i < image.pixelCount(); ++i) {
    const uint32_t w = out.words[i];
    EXPECT_EQ(w >> 24, 255u);
    const uint8_t r = w & 0xFF, g = (w >> 8) & 0xFF, b = (w >> 16) & 0xFF;
    rgb[i * 3] = bgr ? b : r;
    rgb[i * 3 + 1] = g;
    rgb[i * 3 + 2] = bgr ? r : b;
  }
  return rgb;
}

TEST(DisplayPass, SameBytesAsThePngWriter) {
  VulkanContext context;
  createContext(context);
  {
    // Channel values: every float bit pattern step of 2^12 from 0 to 64 (about
    // 135k values, denser than one per byte threshold everywhere), each sRGB
    // threshold and its neighbours, and what the writer maps to black.
    std::vector<float> values;
    const float top = 64.0f;
    uint32_t top_bits;
    std::memcpy(&top_bits, &top, sizeof top);
    for (uint32_t b = 0; b <= top_bits; b += 1u << 12) {
      float v;
      std::memcpy(&v, &b, sizeof v);
      values.push_back(v);
    }
    for (float t : srgb8Thresholds())
      for (float v : {std::nextafter(t, -1.0f), t, std::nextafter(t, 2.0f)}) values.push_back(v);
    for (float v : {-1.0f, -0.0f, std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                    std::numeric_limits<float>::quiet_NaN(), 1e30f})
      values.push_back(v);
    // Pixels mix three different values (the neutral curve works on the pixel).
    const uint32_t width = 509;  // odd: not a multiple of the work group
    const uint32_t height = uint32_t((values.size() + width - 1) / width);
    FloatImage image(width, height);
    const size_t n = values.size();
    for (size_t i = 0; i < image.pixelCount(); ++i) {
      image.rgba[i * 4] = values[i % n];
      image.rgba[i * 4 + 1] = values[(i * 7 + 3) % n];
      image.rgba[i * 4 + 2] = values[(i * 13 + 5) % n];
      image.rgba[i * 4 + 3] = 1.0f;
    }
    DisplayPass pass(context);
    Output out = createOutput(context, VkDeviceSize(image.pixelCount()) * 4);
    for (ToneCurve curve : {ToneCurve::PbrNeutral, ToneCurve::AcesFit, ToneCurve::Clamp})
      for (float stops : {0.0f, -2.25f}) {
        const ToneMap tone{stops, curve};
        const std::vector<uint8_t> expected = toSrgb8(image, tone);
        const std::vector<uint8_t> got = runOnDevice(context, pass, out, image, tone, curve == ToneCurve::AcesFit);
        size_t differ = 0, first = expected.size();
        for (size_t i = 0; i < expected.size(); ++i)
          if (got[i] != expected[i] && differ++ == 0) first = i;
        EXPECT_EQ(differ, 0u) << toneCurveName(curve) << " " << stops << " stops: first at channel value "
                              << (first < expected.size() ? image.rgba[first / 3 * 4 + first % 3] : 0.0f)
                              << " got " << int(first < got.size() ? got[first] : 0) << " expected "
                              << int(first < expected.size() ? expected[first] : 0);
      }
    vkDestroyBuffer(context.device, out.buffer, nullptr);
    vkFreeMemory(context.device, out.memory, nullptr);
  }
  destroyContext(context);
  EXPECT_EQ(validationMessageCount(), 0);
}

}  // namespace
}  // namespace sdfc
