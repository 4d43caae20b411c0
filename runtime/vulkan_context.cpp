#include "vulkan_context.h"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "driver_select.h"
#include "vk_check.h"

namespace sdfc {
namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
constexpr uint32_t kMinApiVersion = VK_API_VERSION_1_1;  // glslToSpirv targets Vulkan 1.1

std::atomic<int> g_validation_messages{0};

VKAPI_ATTR VkBool32 VKAPI_CALL debugCallback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                             VkDebugUtilsMessageTypeFlagsEXT,
                                             const VkDebugUtilsMessengerCallbackDataEXT* data,
                                             void*) {
  const bool is_error = severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  g_validation_messages.fetch_add(1);
  std::fprintf(stderr, "[vulkan %s] %s\n", is_error ? "error" : "warning",
               data && data->pMessage ? data->pMessage : "(no message)");
  return VK_FALSE;  // never abort the call that triggered it
}

VkDebugUtilsMessengerCreateInfoEXT messengerInfo() {
  VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                         VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                     VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                     VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  info.pfnUserCallback = debugCallback;
  return info;
}

bool hasLayer(const char* name) {
  uint32_t count = 0;
  vkEnumerateInstanceLayerProperties(&count, nullptr);
  std::vector<VkLayerProperties> layers(count);
  vkEnumerateInstanceLayerProperties(&count, layers.data());
  for (const auto& layer : layers)
    if (std::strcmp(layer.layerName, name) == 0) return true;
  return false;
}

bool hasInstanceExtension(const char* name) {
  uint32_t count = 0;
  vkEnumerateInstanceExtensionProperties(nullptr, &count, nullptr);
  std::vector<VkExtensionProperties> extensions(count);
  vkEnumerateInstanceExtensionProperties(nullptr, &count, extensions.data());
  for (const auto& extension : extensions)
    if (std::strcmp(extension.extensionName, name) == 0) return true;
  return false;
}

// Creates the instance; `validation` is updated to whether it was really enabled.
VkInstance createInstance(bool& validation,
                          const std::vector<const char*>& extra_extensions = {}) {
  selectedDriver();  // before the loader reads VK_DRIVER_FILES
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "sdfc";
  app.pEngineName = "sdfc";
  app.apiVersion = kMinApiVersion;

  std::vector<const char*> layers;
  std::vector<const char*> extensions = extra_extensions;
  VkDebugUtilsMessengerCreateInfoEXT debug_info = messengerInfo();
  if (validation) {
    const bool layer = hasLayer(kValidationLayer);
    const bool debug_utils = hasInstanceExtension(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    if (!layer) std::fprintf(stderr, "sdfc: %s not installed; validation off\n", kValidationLayer);
    validation = layer && debug_utils;
    if (validation) {
      layers.push_back(kValidationLayer);
      extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    }
  }

  VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  info.pApplicationInfo = &app;
  info.enabledLayerCount = static_cast<uint32_t>(layers.size());
  info.ppEnabledLayerNames = layers.data();
  info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  // Chained messenger info also reports problems during instance creation/destruction.
  if (validation) info.pNext = &debug_info;

  VkInstance instance = VK_NULL_HANDLE;
  VK_CHECK(vkCreateInstance(&info, nullptr, &instance));
  return instance;
}

int graphicsQueueFamily(VkPhysicalDevice device) {
  uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, families.data());
  for (uint32_t i = 0; i < count; ++i)
    if (families[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) return static_cast<int>(i);
  return -1;
}

std::vector<VkPhysicalDevice> physicalDevices(VkInstance instance) {
  uint32_t count = 0;
  VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, nullptr));
  std::vector<VkPhysicalDevice> devices(count);
  VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, devices.data()));
  return devices;
}

DeviceInfo describe(VkPhysicalDevice device, uint32_t index) {
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(device, &props);
  DeviceInfo info;
  info.index = index;
  info.name = props.deviceName;
  info.type = props.deviceType;
  info.api_version = props.apiVersion;
  info.usable = graphicsQueueFamily(device) >= 0 && props.apiVersion >= kMinApiVersion;
  info.driver = driverText(device);
  return info;
}

// Lower is better: GPUs first, CPU rasterisers (lavapipe) last.
int typeRank(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 4;
    default: return 3;
  }
}

}  // namespace

bool ContextOptions::validationRequestedByEnv() {
  const char* value = std::getenv("SDFC_VALIDATION");
  return value && std::strcmp(value, "1") == 0;
}

const char* deviceTypeName(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete GPU";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated GPU";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual GPU";
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "CPU";
    default: return "other";
  }
}

bool driverCapsLoops(const VkPhysicalDeviceProperties& props) {
  // Measured (docs/lavapipe.md): lavapipe of Vulkan 1.3 (Mesa 22.3.6) caps,
  // that of Vulkan 1.4 (Mesa 25.0.7) does not; a GPU does not. A CPU device
  // we have not measured is assumed to cap (rationed visits cost only time).
  return props.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU && VK_API_VERSION_MINOR(props.apiVersion) <= 3;
}

std::string driverText(VkPhysicalDevice device) {
  // driverInfo ("Mesa 25.0.7-2~bpo12+1 (LLVM 15.0.6)") when the device has
  // VK_KHR_driver_properties (core in 1.2; both lavapipes have it): lavapipe's
  // driverVersion is a constant 1, so it cannot tell two Mesa releases apart.
  uint32_t count = 0;
  vkEnumerateDeviceExtensionProperties(device, nullptr, &count, nullptr);
  std::vector<VkExtensionProperties> extensions(count);
  vkEnumerateDeviceExtensionProperties(device, nullptr, &count, extensions.data());
  for (const auto& e : extensions) {
    if (std::strcmp(e.extensionName, VK_KHR_DRIVER_PROPERTIES_EXTENSION_NAME) != 0) continue;
    VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
    VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    props.pNext = &driver;
    vkGetPhysicalDeviceProperties2(device, &props);
    std::string info = driver.driverInfo;
    const size_t tilde = info.find('~');  // Debian's backport suffix: keep "Mesa 25.0.7"
    const size_t dash = info.find('-');
    if (info.rfind("Mesa ", 0) == 0) info = info.substr(0, std::min({tilde, dash, info.find(' ', 5)}));
    return info.empty() ? std::string(driver.driverName) : info;
  }
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(device, &props);
  char text[64];
  std::snprintf(text, sizeof(text), "driver version 0x%x", props.driverVersion);
  return text;
}

int validationMessageCount() { return g_validation_messages.load(); }

std::vector<DeviceInfo> listDevices() {
  bool validation = false;
  VkInstance instance = createInstance(validation);
  std::vector<DeviceInfo> result;
  try {
    const auto devices = physicalDevices(instance);
    for (uint32_t i = 0; i < devices.size(); ++i) result.push_back(describe(devices[i], i));
  } catch (...) {
    vkDestroyInstance(instance, nullptr);
    throw;
  }
  vkDestroyInstance(instance, nullptr);
  return result;
}

void createContext(VulkanContext& context, const ContextOptions& options) {
  context = {};
  bool validation = options.validation;
  context.instance = createInstance(validation, options.instance_extensions);
  context.validation_enabled = validation;
  try {
    if (validation) {
      auto create_messenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(context.instance, "vkCreateDebugUtilsMessengerEXT"));
      const VkDebugUtilsMessengerCreateInfoEXT info = messengerInfo();
      if (create_messenger)
        VK_CHECK(create_messenger(context.instance, &info, nullptr, &context.messenger));
    }

    const auto devices = physicalDevices(context.instance);
    int chosen = -1;
    if (options.device_index >= 0) {
      if (options.device_index >= static_cast<int>(devices.size()))
        throw RuntimeError("no Vulkan device with index " + std::to_string(options.device_index) +
                           " (found " + std::to_string(devices.size()) + ")");
      const DeviceInfo info = describe(devices[options.device_index], options.device_index);
      if (!info.usable)
        throw RuntimeError("Vulkan device " + info.name +
                           " lacks a graphics queue or Vulkan 1.1");
      chosen = options.device_index;
    } else {
      int best_rank = 1 << 30;
      for (uint32_t i = 0; i < devices.size(); ++i) {
        const DeviceInfo info = describe(devices[i], i);
        if (info.usable && typeRank(info.type) < best_rank) {
          best_rank = typeRank(info.type);
          chosen = static_cast<int>(i);
        }
      }
      if (chosen < 0) throw RuntimeError("no usable Vulkan device (graphics queue, Vulkan 1.1)");
    }

    context.physical_device = devices[chosen];
    vkGetPhysicalDeviceProperties(context.physical_device, &context.properties);
    context.loop_cap = driverCapsLoops(context.properties);
    vkGetPhysicalDeviceMemoryProperties(context.physical_device, &context.memory_properties);
    context.queue_family = static_cast<uint32_t>(graphicsQueueFamily(context.physical_device));

    const float priority = 1.0f;
    VkDeviceQueueCreateInfo queue_info{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    queue_info.queueFamilyIndex = context.queue_family;
    queue_info.queueCount = 1;
    queue_info.pQueuePriorities = &priority;
    VkDeviceCreateInfo device_info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    device_info.queueCreateInfoCount = 1;
    device_info.pQueueCreateInfos = &queue_info;
    device_info.enabledExtensionCount = static_cast<uint32_t>(options.device_extensions.size());
    device_info.ppEnabledExtensionNames = options.device_extensions.data();
    VK_CHECK(vkCreateDevice(context.physical_device, &device_info, nullptr, &context.device));
    vkGetDeviceQueue(context.device, context.queue_family, 0, &context.queue);

    VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pool_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pool_info.queueFamilyIndex = context.queue_family;
    VK_CHECK(vkCreateCommandPool(context.device, &pool_info, nullptr, &context.command_pool));
    context.queue_lock = std::make_shared<std::recursive_mutex>();
  } catch (...) {
    destroyContext(context);
    throw;
  }
}

void destroyContext(VulkanContext& context) {
  if (context.device) {
    vkDeviceWaitIdle(context.device);
    if (context.command_pool) vkDestroyCommandPool(context.device, context.command_pool, nullptr);
    vkDestroyDevice(context.device, nullptr);
  }
  if (context.messenger) {
    auto destroy_messenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(context.instance, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy_messenger) destroy_messenger(context.instance, context.messenger, nullptr);
  }
  if (context.instance) vkDestroyInstance(context.instance, nullptr);
  context = {};
}

uint32_t findMemoryType(const VulkanContext& context, uint32_t type_bits,
                        VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred) {
  const auto& mem = context.memory_properties;
  const VkMemoryPropertyFlags wanted[2] = {required | preferred, required};
  for (VkMemoryPropertyFlags flags : wanted)
    for (uint32_t i = 0; i < mem.memoryTypeCount; ++i)
      if ((type_bits & (1u << i)) && (mem.memoryTypes[i].propertyFlags & flags) == flags) return i;
  throw RuntimeError("no Vulkan memory type with the required properties");
}

}  // namespace sdfc
