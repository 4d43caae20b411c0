// The swapchain on the renderer's device and queue, and a frame into it. The
// renderer draws offscreen and reads back (it is shared with `sdfc render`); the
// view hands the frame's floats to the device's tone map (display_pass.h), whose
// bytes are copied into the acquired image in the same submission, so what is
// presented is byte for byte what `save` would write as PNG. Frames with the error
// overlay come as 8-bit bytes from the CPU instead.
#pragma once
#include <vulkan/vulkan.h>

#include <cstdint>
#include <functional>
#include <vector>

#include "display_pass.h"
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
  // `rgb` may be reused at once.
  void present(const uint8_t* rgb, uint32_t width, uint32_t height);
  // Presents `display`'s input (written by the caller after waitForLastFrame),
  // tone-mapped on the device and enlarged by `scale`, cut to width x height
  // (the window's size). Returns without waiting for the device.
  void present(DisplayPass& display, const ToneMap& tone, uint32_t source_width, uint32_t source_height,
               uint32_t scale, uint32_t width, uint32_t height);
  // Waits until the last present's submission is done (its staging and the
  // display pass's input may be written again); milliseconds waited.
  double waitForLastFrame();
  // FNV-1a over the last presented frame's pixels as R | G << 8 | B << 16 words
  // (the frame log's hash), after waiting for it; 0 before the first.
  uint64_t lastFrameHash();
  // The window's new size: the swapchain is made again, at it, before the next
  // present (as it is after VK_ERROR_OUT_OF_DATE_KHR or VK_SUBOPTIMAL_KHR).
  void resize(uint32_t width, uint32_t height);
  // The last present()'s parts, in milliseconds (--timings, the frame log).
  struct Times {
    double acquire = 0;  // vkAcquireNextImageKHR (the device waits for its image)
    double copy = 0;     // the commands (or CPU bytes into staging) and their submission
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
  // Acquire, `record` the commands that fill staging_, copy it into the image,
  // submit and present; false when there was nothing to present to.
  bool presentWith(const std::function<void(VkCommandBuffer)>& record, const std::function<void()>& fill);

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
  // One frame in flight: the acquire's semaphore, one "copied" semaphore per
  // image (an image's present is done when it is acquired again), a fence per
  // submission that the next frame waits for before it writes staging again.
  VkSemaphore acquired_ = VK_NULL_HANDLE;
  std::vector<VkSemaphore> copied_;
  VkFence frame_fence_ = VK_NULL_HANDLE;
  bool in_flight_ = false;
  bool presented_ = false;
  bool stale_ = false;  // out of date or suboptimal: recreate before the next frame
  uint32_t generation_ = 0;
  Times times_;
};

}  // namespace sdfc::view
