// The swapchain on the renderer's device and queue, and the upload of a finished
// 8-bit frame into it. The renderer draws offscreen and reads back (it is shared
// with `sdfc render`); the view copies the tone-mapped bytes into the acquired image,
// so what is presented is byte for byte what `save` would write as PNG.
#pragma once
#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

#include "vulkan_context.h"

namespace sdfc::view {

class Swapchain {
 public:
  // `surface` must outlive the swapchain; throws RuntimeError when the device's
  // queue cannot present to it or its images cannot be transfer destinations.
  Swapchain(const VulkanContext& context, VkSurfaceKHR surface, uint32_t width, uint32_t height);
  ~Swapchain();
  Swapchain(const Swapchain&) = delete;
  Swapchain& operator=(const Swapchain&) = delete;

  // Presents `rgb` (width x height x 3 bytes, top row first, sRGB-encoded: toSrgb8's
  // output). Parts outside the swapchain's extent are cut, uncovered parts black.
  // Waits until the copy is done, so `rgb` may be reused at once.
  void present(const uint8_t* rgb, uint32_t width, uint32_t height);
  // The window's new size: the swapchain is made again, at it, before the next
  // present (as it is after VK_ERROR_OUT_OF_DATE_KHR or VK_SUBOPTIMAL_KHR).
  void resize(uint32_t width, uint32_t height);
  // The last present()'s parts, in milliseconds (--timings, the frame log).
  struct Times {
    double acquire = 0;  // vkAcquireNextImageKHR and the wait for its image
    double copy = 0;     // the bytes into staging, the copy's submission and its wait
    double present = 0;  // vkQueuePresentKHR
  };
  const Times& lastTimes() const { return times_; }
  // Swapchains made so far (the first included): tests see a resize recreate it.
  uint32_t generation() const { return generation_; }

  uint32_t width() const { return extent_.width; }
  uint32_t height() const { return extent_.height; }
  const char* presentModeName() const;

 private:
  void create();
  void destroy();

  const VulkanContext& context_;
  VkSurfaceKHR surface_;
  uint32_t requested_width_, requested_height_;
  VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  bool bgr_ = false;  // the image's byte order is B, G, R, A
  VkPresentModeKHR present_mode_ = VK_PRESENT_MODE_FIFO_KHR;
  VkExtent2D extent_{};
  std::vector<VkImage> images_;
  VkBuffer staging_ = VK_NULL_HANDLE;
  VkDeviceMemory staging_memory_ = VK_NULL_HANDLE;
  uint8_t* mapped_ = nullptr;
  bool staging_coherent_ = false;
  VkCommandBuffer command_buffer_ = VK_NULL_HANDLE;
  VkFence acquire_fence_ = VK_NULL_HANDLE, copy_fence_ = VK_NULL_HANDLE;
  bool stale_ = false;  // out of date or suboptimal: recreate before the next frame
  uint32_t generation_ = 0;
  Times times_;
};

}  // namespace sdfc::view
