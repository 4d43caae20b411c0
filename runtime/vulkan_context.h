// The Vulkan instance, one physical device, one graphics queue and a command
// pool. Headless unless ContextOptions asks for window-system extensions. Plain struct + create/destroy.
#pragma once
#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace sdfc {

struct DeviceInfo {
  uint32_t index = 0;  // position in vkEnumeratePhysicalDevices order
  std::string name;
  VkPhysicalDeviceType type = VK_PHYSICAL_DEVICE_TYPE_OTHER;
  uint32_t api_version = 0;
  bool usable = false;  // has a graphics queue and Vulkan >= 1.1
  std::string driver;   // e.g. "Mesa 25.0.7" (driverText)
};

const char* deviceTypeName(VkPhysicalDeviceType type);
// The driver's release, e.g. "Mesa 25.0.7" (from VkPhysicalDeviceDriverProperties),
// else the raw driverVersion in hex.
std::string driverText(VkPhysicalDevice device);
// Whether the device's driver caps loop iterations (VulkanContext::loop_cap).
bool driverCapsLoops(const VkPhysicalDeviceProperties& props);

// All physical devices (creates and destroys a temporary instance).
std::vector<DeviceInfo> listDevices();

struct ContextOptions {
  // -1: prefer a discrete GPU, then integrated, virtual, and finally a CPU
  // device such as lavapipe. Otherwise the index from listDevices().
  int device_index = -1;
  // Validation layer + debug messenger; by default on iff env SDFC_VALIDATION=1.
  bool validation = validationRequestedByEnv();
  // Extra extensions, e.g. a window system's surface extensions (instance) and
  // VK_KHR_swapchain (device) for `sdfc view`; headless renders need none.
  std::vector<const char*> instance_extensions;
  std::vector<const char*> device_extensions;

  static bool validationRequestedByEnv();
};

struct VulkanContext {
  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  VkPhysicalDevice physical_device = VK_NULL_HANDLE;
  VkPhysicalDeviceProperties properties{};
  VkPhysicalDeviceMemoryProperties memory_properties{};
  VkDevice device = VK_NULL_HANDLE;
  uint32_t queue_family = 0;
  VkQueue queue = VK_NULL_HANDLE;
  VkCommandPool command_pool = VK_NULL_HANDLE;
  bool validation_enabled = false;  // the layer was found and enabled
  // The driver ends a shader invocation's loops after gpu::kLavapipeLoopCap
  // iterations in total (Mesa 22.3.6's lavapipe; 25.0.7's and GPUs' do not:
  // DriverFacts.LoopCapIsMeasured). Then hierarchy visits are rationed
  // (runtime/loop_budget.h); without it a traversal runs to its end, exact.
  bool loop_cap = true;
  // Held by whoever submits to or waits on `queue` (vkQueueSubmit, present,
  // vkDeviceWaitIdle need the queue externally synchronised). `sdfc view`'s
  // worker thread draws a new kernel once to have the driver compile it; the frame
  // loop try-locks this and, while the worker has it, skips its frame instead of
  // waiting behind the compile. Recursive: a frame holds it around its passes.
  std::shared_ptr<std::recursive_mutex> queue_lock;

  std::string deviceName() const { return properties.deviceName; }
};

// The context's queue lock held for a scope (nothing when the context has none).
inline std::unique_lock<std::recursive_mutex> lockQueue(const VulkanContext& context) {
  return context.queue_lock ? std::unique_lock<std::recursive_mutex>(*context.queue_lock)
                            : std::unique_lock<std::recursive_mutex>();
}

// Throws RuntimeError when no usable device exists or the index is invalid.
void createContext(VulkanContext& context, const ContextOptions& options = {});
void destroyContext(VulkanContext& context);

// A context for one scope: created by the constructor (which throws as
// createContext does), destroyed on every way out of the scope.
class ScopedContext {
 public:
  explicit ScopedContext(const ContextOptions& options = {}) { createContext(context_, options); }
  ~ScopedContext() { destroyContext(context_); }
  ScopedContext(const ScopedContext&) = delete;
  ScopedContext& operator=(const ScopedContext&) = delete;
  VulkanContext& get() { return context_; }

 private:
  VulkanContext context_;
};

// Validation warnings and errors reported since program start (all contexts).
// Each is also printed to stderr. Tests assert this stays 0.
int validationMessageCount();

// Index of a memory type allowed by `type_bits` with all `required` flags;
// prefers one that also has `preferred`. Throws when there is none.
uint32_t findMemoryType(const VulkanContext& context, uint32_t type_bits,
                        VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred = 0);

}  // namespace sdfc
