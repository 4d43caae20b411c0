#include "swapchain.h"

#include <chrono>

#include <algorithm>
#include <cstring>

#include "vk_check.h"

namespace sdfc::view {
namespace {

constexpr uint64_t kWaitNs = 10ull * 1000 * 1000 * 1000;  // lavapipe has no watchdog

void waitFence(VkDevice device, VkFence fence) {
  const VkResult r = vkWaitForFences(device, 1, &fence, VK_TRUE, kWaitNs);
  if (r == VK_TIMEOUT) throw RuntimeError("presenting a frame took more than 10 s");
  if (r != VK_SUCCESS) throwVkError(r, "vkWaitForFences", __FILE__, __LINE__);
  VK_CHECK(vkResetFences(device, 1, &fence));
}

}  // namespace

Swapchain::Swapchain(const VulkanContext& context, VkSurfaceKHR surface, uint32_t width,
                     uint32_t height)
    : context_(context), surface_(surface), requested_width_(width), requested_height_(height) {
  VkBool32 supported = VK_FALSE;
  VK_CHECK(vkGetPhysicalDeviceSurfaceSupportKHR(context.physical_device, context.queue_family,
                                                surface, &supported));
  if (!supported)
    throw RuntimeError("the device " + context.deviceName() + " cannot present to this window");
  VkCommandBufferAllocateInfo cb{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cb.commandPool = context.command_pool;
  cb.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cb.commandBufferCount = 1;
  VK_CHECK(vkAllocateCommandBuffers(context.device, &cb, &command_buffer_));
  VkFenceCreateInfo fence{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VK_CHECK(vkCreateFence(context.device, &fence, nullptr, &acquire_fence_));
  VK_CHECK(vkCreateFence(context.device, &fence, nullptr, &copy_fence_));
  try {
    create();
  } catch (...) {
    destroy();
    vkDestroyFence(context.device, acquire_fence_, nullptr);
    vkDestroyFence(context.device, copy_fence_, nullptr);
    vkFreeCommandBuffers(context.device, context.command_pool, 1, &command_buffer_);
    throw;
  }
}

Swapchain::~Swapchain() {
  destroy();
  vkDestroyFence(context_.device, acquire_fence_, nullptr);
  vkDestroyFence(context_.device, copy_fence_, nullptr);
  vkFreeCommandBuffers(context_.device, context_.command_pool, 1, &command_buffer_);
}

const char* Swapchain::presentModeName() const {
  switch (present_mode_) {
    case VK_PRESENT_MODE_IMMEDIATE_KHR: return "immediate";
    case VK_PRESENT_MODE_MAILBOX_KHR: return "mailbox";
    case VK_PRESENT_MODE_FIFO_KHR: return "fifo";
    default: return "other";
  }
}

void Swapchain::create() {
  VkPhysicalDevice gpu = context_.physical_device;
  VkDevice device = context_.device;
  VkSurfaceCapabilitiesKHR caps{};
  VK_CHECK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(gpu, surface_, &caps));
  if (!(caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT))
    throw RuntimeError("the window's swapchain images cannot be copied to");

  uint32_t count = 0;
  VK_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(gpu, surface_, &count, nullptr));
  std::vector<VkSurfaceFormatKHR> formats(count);
  VK_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(gpu, surface_, &count, formats.data()));
  // UNORM: the bytes are sRGB-encoded already (as in the PNG writer).
  VkSurfaceFormatKHR chosen{VK_FORMAT_UNDEFINED, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR};
  for (const auto& f : formats)
    if (f.format == VK_FORMAT_B8G8R8A8_UNORM || f.format == VK_FORMAT_R8G8B8A8_UNORM) {
      chosen = f;
      break;
    }
  if (chosen.format == VK_FORMAT_UNDEFINED) {
    if (formats.empty()) throw RuntimeError("the window offers no surface format");
    chosen = formats[0];
  }
  format_ = chosen.format;
  bgr_ = format_ == VK_FORMAT_B8G8R8A8_UNORM || format_ == VK_FORMAT_B8G8R8A8_SRGB;

  VK_CHECK(vkGetPhysicalDeviceSurfacePresentModesKHR(gpu, surface_, &count, nullptr));
  std::vector<VkPresentModeKHR> modes(count);
  VK_CHECK(vkGetPhysicalDeviceSurfacePresentModesKHR(gpu, surface_, &count, modes.data()));
  // The frame rate is set by rendering, not by the display: never wait for vblank.
  present_mode_ = VK_PRESENT_MODE_FIFO_KHR;
  for (VkPresentModeKHR wanted : {VK_PRESENT_MODE_MAILBOX_KHR, VK_PRESENT_MODE_IMMEDIATE_KHR})
    if (std::find(modes.begin(), modes.end(), wanted) != modes.end()) present_mode_ = wanted;

  extent_ = caps.currentExtent;
  if (extent_.width == 0xFFFFFFFFu) {
    extent_.width = std::clamp(requested_width_, caps.minImageExtent.width, caps.maxImageExtent.width);
    extent_.height =
        std::clamp(requested_height_, caps.minImageExtent.height, caps.maxImageExtent.height);
  }
  if (extent_.width == 0 || extent_.height == 0) return;  // minimised: nothing to present to
  uint32_t image_count = caps.minImageCount + 1;
  if (caps.maxImageCount > 0) image_count = std::min(image_count, caps.maxImageCount);

  VkSwapchainCreateInfoKHR info{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
  info.surface = surface_;
  info.minImageCount = image_count;
  info.imageFormat = chosen.format;
  info.imageColorSpace = chosen.colorSpace;
  info.imageExtent = extent_;
  info.imageArrayLayers = 1;
  info.imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
  info.preTransform = caps.currentTransform;
  info.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
  if (!(caps.supportedCompositeAlpha & info.compositeAlpha))
    info.compositeAlpha = static_cast<VkCompositeAlphaFlagBitsKHR>(
        caps.supportedCompositeAlpha & -caps.supportedCompositeAlpha);  // lowest set bit
  info.presentMode = present_mode_;
  info.clipped = VK_TRUE;
  VK_CHECK(vkCreateSwapchainKHR(device, &info, nullptr, &swapchain_));
  VK_CHECK(vkGetSwapchainImagesKHR(device, swapchain_, &count, nullptr));
  images_.resize(count);
  VK_CHECK(vkGetSwapchainImagesKHR(device, swapchain_, &count, images_.data()));

  VkBufferCreateInfo buffer{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  buffer.size = VkDeviceSize(extent_.width) * extent_.height * 4;
  buffer.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
  VK_CHECK(vkCreateBuffer(device, &buffer, nullptr, &staging_));
  VkMemoryRequirements reqs{};
  vkGetBufferMemoryRequirements(device, staging_, &reqs);
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  alloc.allocationSize = reqs.size;
  alloc.memoryTypeIndex = findMemoryType(context_, reqs.memoryTypeBits,
                                         VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT,
                                         VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  staging_coherent_ = context_.memory_properties.memoryTypes[alloc.memoryTypeIndex].propertyFlags &
                      VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  VK_CHECK(vkAllocateMemory(device, &alloc, nullptr, &staging_memory_));
  VK_CHECK(vkBindBufferMemory(device, staging_, staging_memory_, 0));
  void* mapped = nullptr;
  VK_CHECK(vkMapMemory(device, staging_memory_, 0, VK_WHOLE_SIZE, 0, &mapped));
  mapped_ = static_cast<uint8_t*>(mapped);
  stale_ = false;
  ++generation_;
}

void Swapchain::resize(uint32_t width, uint32_t height) {
  if (width == requested_width_ && height == requested_height_) return;
  requested_width_ = width;
  requested_height_ = height;
  stale_ = true;
}

void Swapchain::destroy() {
  VkDevice device = context_.device;
  const auto lock = lockQueue(context_);
  vkDeviceWaitIdle(device);
  if (staging_) vkDestroyBuffer(device, staging_, nullptr);
  if (staging_memory_) vkFreeMemory(device, staging_memory_, nullptr);
  if (swapchain_) vkDestroySwapchainKHR(device, swapchain_, nullptr);
  staging_ = VK_NULL_HANDLE;
  staging_memory_ = VK_NULL_HANDLE;
  swapchain_ = VK_NULL_HANDLE;
  mapped_ = nullptr;
  images_.clear();
}

void Swapchain::present(const uint8_t* rgb, uint32_t width, uint32_t height) {
  VkDevice device = context_.device;
  const auto lock = lockQueue(context_);
  using Clock = std::chrono::steady_clock;
  const auto ms = [](Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
  };
  times_ = {};
  if (stale_ || !swapchain_) {
    destroy();
    create();
    if (!swapchain_) return;
  }
  const auto acquire_start = Clock::now();
  uint32_t index = 0;
  VkResult r = vkAcquireNextImageKHR(device, swapchain_, kWaitNs, VK_NULL_HANDLE, acquire_fence_,
                                     &index);
  if (r == VK_ERROR_OUT_OF_DATE_KHR) {
    stale_ = true;
    return;
  }
  if (r == VK_TIMEOUT) throw RuntimeError("no swapchain image within 10 s");
  if (r != VK_SUCCESS && r != VK_SUBOPTIMAL_KHR)
    throwVkError(r, "vkAcquireNextImageKHR", __FILE__, __LINE__);
  if (r == VK_SUBOPTIMAL_KHR) stale_ = true;
  waitFence(device, acquire_fence_);
  const auto copy_start = Clock::now();
  times_.acquire = ms(acquire_start, copy_start);

  // Rows into the staging buffer in the image's byte order; black where uncovered.
  const uint32_t w = extent_.width, h = extent_.height;
  for (uint32_t y = 0; y < h; ++y) {
    uint8_t* row = mapped_ + size_t(y) * w * 4;
    const uint32_t covered = y < height ? std::min(w, width) : 0;
    const uint8_t* source = rgb + size_t(y) * width * 3;
    const int r = bgr_ ? 2 : 0, b = bgr_ ? 0 : 2;
    for (uint32_t x = 0; x < covered; ++x) {
      row[4 * x + r] = source[3 * x + 0];
      row[4 * x + 1] = source[3 * x + 1];
      row[4 * x + b] = source[3 * x + 2];
      row[4 * x + 3] = 255;
    }
    std::memset(row + size_t(covered) * 4, 0, size_t(w - covered) * 4);
  }
  if (!staging_coherent_) {
    VkMappedMemoryRange range{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE};
    range.memory = staging_memory_;
    range.size = VK_WHOLE_SIZE;
    VK_CHECK(vkFlushMappedMemoryRanges(device, 1, &range));
  }

  VkCommandBuffer cmd = command_buffer_;
  VK_CHECK(vkResetCommandBuffer(cmd, 0));
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_CHECK(vkBeginCommandBuffer(cmd, &begin));
  VkImageMemoryBarrier barrier{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  barrier.srcAccessMask = 0;
  barrier.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  barrier.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  barrier.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.image = images_[index];
  barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0,
                       nullptr, 0, nullptr, 1, &barrier);
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {w, h, 1};
  vkCmdCopyBufferToImage(cmd, staging_, images_[index], VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                         &region);
  barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  barrier.dstAccessMask = 0;
  barrier.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  barrier.newLayout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0,
                       0, nullptr, 0, nullptr, 1, &barrier);
  VK_CHECK(vkEndCommandBuffer(cmd));
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cmd;
  VK_CHECK(vkQueueSubmit(context_.queue, 1, &submit, copy_fence_));
  waitFence(device, copy_fence_);  // the copy is done: no semaphore needed for present
  const auto present_start = Clock::now();
  times_.copy = ms(copy_start, present_start);

  VkPresentInfoKHR present{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
  present.swapchainCount = 1;
  present.pSwapchains = &swapchain_;
  present.pImageIndices = &index;
  r = vkQueuePresentKHR(context_.queue, &present);
  times_.present = ms(present_start, Clock::now());
  if (r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_SUBOPTIMAL_KHR)
    stale_ = true;
  else if (r != VK_SUCCESS)
    throwVkError(r, "vkQueuePresentKHR", __FILE__, __LINE__);
}

}  // namespace sdfc::view
