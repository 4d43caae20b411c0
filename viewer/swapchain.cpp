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
  VK_CHECK(vkCreateFence(context.device, &fence, nullptr, &frame_fence_));
  VkSemaphoreCreateInfo semaphore{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  VK_CHECK(vkCreateSemaphore(context.device, &semaphore, nullptr, &acquired_));
  try {
    create();
  } catch (...) {
    destroy();
    vkDestroyFence(context.device, frame_fence_, nullptr);
    vkDestroySemaphore(context.device, acquired_, nullptr);
    vkFreeCommandBuffers(context.device, context.command_pool, 1, &command_buffer_);
    throw;
  }
}

Swapchain::~Swapchain() {
  destroy();
  vkDestroyFence(context_.device, frame_fence_, nullptr);
  vkDestroySemaphore(context_.device, acquired_, nullptr);
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
  // Written by the CPU (the error overlay's frames) or by the display pass.
  buffer.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
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
  VkSemaphoreCreateInfo semaphore{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  copied_.resize(images_.size());
  for (VkSemaphore& s : copied_) VK_CHECK(vkCreateSemaphore(device, &semaphore, nullptr, &s));
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
  for (VkSemaphore s : copied_) vkDestroySemaphore(device, s, nullptr);
  copied_.clear();
  if (in_flight_) VK_CHECK(vkResetFences(device, 1, &frame_fence_));  // signalled: idle
  in_flight_ = false;
  presented_ = false;
  staging_ = VK_NULL_HANDLE;
  staging_memory_ = VK_NULL_HANDLE;
  swapchain_ = VK_NULL_HANDLE;
  mapped_ = nullptr;
  images_.clear();
}

double Swapchain::waitForLastFrame() {
  if (!in_flight_) return 0;
  const auto lock = lockQueue(context_);
  const auto start = std::chrono::steady_clock::now();
  waitFence(context_.device, frame_fence_);
  in_flight_ = false;
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

uint64_t Swapchain::lastFrameHash() {
  if (!presented_ || !mapped_) return 0;
  waitForLastFrame();
  const uint32_t* words = reinterpret_cast<const uint32_t*>(mapped_);
  const size_t n = size_t(extent_.width) * extent_.height;
  uint64_t h = 1469598103934665603ull;
  for (size_t i = 0; i < n; ++i) {
    uint32_t w = words[i];
    if (bgr_) w = ((w >> 16) & 0xFF) | (w & 0xFF00) | ((w & 0xFF) << 16);
    h = (h ^ (w & 0xFFFFFF)) * 1099511628211ull;
  }
  return h;
}

void Swapchain::present(const uint8_t* rgb, uint32_t width, uint32_t height) {
  presentWith(nullptr, [&] {
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
      VK_CHECK(vkFlushMappedMemoryRanges(context_.device, 1, &range));
    }
  });
}

void Swapchain::present(DisplayPass& display, const ToneMap& tone, uint32_t source_width,
                        uint32_t source_height, uint32_t scale, uint32_t width, uint32_t height) {
  presentWith(
      [&](VkCommandBuffer cmd) {
        DisplayLayout layout;
        layout.width = source_width;
        layout.height = source_height;
        layout.scale = scale;
        layout.out_width = extent_.width;
        layout.out_height = extent_.height;
        layout.covered_width = std::min(width, extent_.width);
        layout.covered_height = std::min(height, extent_.height);
        layout.bgr = bgr_;
        display.record(cmd, tone, layout, staging_, VkDeviceSize(extent_.width) * extent_.height * 4);
      },
      nullptr);
}

bool Swapchain::presentWith(const std::function<void(VkCommandBuffer)>& record,
                            const std::function<void()>& fill) {
  VkDevice device = context_.device;
  const auto lock = lockQueue(context_);
  using Clock = std::chrono::steady_clock;
  const auto ms = [](Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
  };
  times_ = {};
  const auto start = Clock::now();
  waitForLastFrame();  // staging and the command buffer are free again
  if (stale_ || !swapchain_) {
    destroy();
    create();
    if (!swapchain_) return false;
  }
  const auto acquire_start = Clock::now();
  uint32_t index = 0;
  VkResult r = vkAcquireNextImageKHR(device, swapchain_, kWaitNs, acquired_, VK_NULL_HANDLE, &index);
  if (r == VK_ERROR_OUT_OF_DATE_KHR) {
    stale_ = true;
    return false;
  }
  if (r == VK_TIMEOUT) throw RuntimeError("no swapchain image within 10 s");
  if (r != VK_SUCCESS && r != VK_SUBOPTIMAL_KHR)
    throwVkError(r, "vkAcquireNextImageKHR", __FILE__, __LINE__);
  if (r == VK_SUBOPTIMAL_KHR) stale_ = true;
  const auto copy_start = Clock::now();
  times_.acquire = ms(acquire_start, copy_start) + ms(start, acquire_start);
  if (fill) fill();

  const uint32_t w = extent_.width, h = extent_.height;
  VkCommandBuffer cmd = command_buffer_;
  VK_CHECK(vkResetCommandBuffer(cmd, 0));
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_CHECK(vkBeginCommandBuffer(cmd, &begin));
  if (record) record(cmd);
  VkImageMemoryBarrier barrier{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  barrier.srcAccessMask = 0;
  barrier.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  barrier.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  barrier.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.image = images_[index];
  barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  // After the acquire's semaphore (waited at the transfer stage).
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0,
                       nullptr, 1, &barrier);
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {w, h, 1};
  vkCmdCopyBufferToImage(cmd, staging_, images_[index], VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
  barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  barrier.dstAccessMask = 0;
  barrier.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  barrier.newLayout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0, 0, nullptr,
                       0, nullptr, 1, &barrier);
  VK_CHECK(vkEndCommandBuffer(cmd));
  const VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_TRANSFER_BIT;
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.waitSemaphoreCount = 1;
  submit.pWaitSemaphores = &acquired_;
  submit.pWaitDstStageMask = &wait_stage;
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cmd;
  submit.signalSemaphoreCount = 1;
  submit.pSignalSemaphores = &copied_[index];
  VK_CHECK(vkQueueSubmit(context_.queue, 1, &submit, frame_fence_));
  in_flight_ = true;
  presented_ = true;
  const auto present_start = Clock::now();
  times_.copy = ms(copy_start, present_start);

  // No wait here: the present waits for the copy on the device (the semaphore).
  VkPresentInfoKHR present{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
  present.waitSemaphoreCount = 1;
  present.pWaitSemaphores = &copied_[index];
  present.swapchainCount = 1;
  present.pSwapchains = &swapchain_;
  present.pImageIndices = &index;
  r = vkQueuePresentKHR(context_.queue, &present);
  times_.present = ms(present_start, Clock::now());
  if (r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_SUBOPTIMAL_KHR)
    stale_ = true;
  else if (r != VK_SUCCESS)
    throwVkError(r, "vkQueuePresentKHR", __FILE__, __LINE__);
  return true;
}

}  // namespace sdfc::view
