// Error handling for Vulkan calls: VK_CHECK throws sdfc::RuntimeError (never
// aborts) so the CLI can report the failure and exit with a device error code.
#pragma once
#include <vulkan/vulkan.h>

#include <stdexcept>
#include <string>

namespace sdfc {

// Any failure of the Vulkan runtime (device loss, timeout, missing feature).
class RuntimeError : public std::runtime_error {
 public:
  explicit RuntimeError(const std::string& message) : std::runtime_error(message) {}
};

// "VK_ERROR_DEVICE_LOST" etc.; "VkResult(<n>)" for codes this build does not know.
const char* vkResultName(VkResult result);

[[noreturn]] void throwVkError(VkResult result, const char* call, const char* file, int line);

}  // namespace sdfc

// Evaluates `call` once; anything other than VK_SUCCESS throws, naming file:line,
// the call text and the VkResult.
#define VK_CHECK(call)                                                   \
  do {                                                                   \
    const VkResult vk_check_result_ = (call);                            \
    if (vk_check_result_ != VK_SUCCESS)                                  \
      ::sdfc::throwVkError(vk_check_result_, #call, __FILE__, __LINE__); \
  } while (0)
