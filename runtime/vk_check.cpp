#include "vk_check.h"

#include <filesystem>

namespace sdfc {

const char* vkResultName(VkResult result) {
  switch (result) {
#define SDFC_VK_RESULT_CASE(r) \
  case r:                      \
    return #r;
    SDFC_VK_RESULT_CASE(VK_SUCCESS)
    SDFC_VK_RESULT_CASE(VK_NOT_READY)
    SDFC_VK_RESULT_CASE(VK_TIMEOUT)
    SDFC_VK_RESULT_CASE(VK_EVENT_SET)
    SDFC_VK_RESULT_CASE(VK_EVENT_RESET)
    SDFC_VK_RESULT_CASE(VK_INCOMPLETE)
    SDFC_VK_RESULT_CASE(VK_ERROR_OUT_OF_HOST_MEMORY)
    SDFC_VK_RESULT_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    SDFC_VK_RESULT_CASE(VK_ERROR_INITIALIZATION_FAILED)
    SDFC_VK_RESULT_CASE(VK_ERROR_DEVICE_LOST)
    SDFC_VK_RESULT_CASE(VK_ERROR_MEMORY_MAP_FAILED)
    SDFC_VK_RESULT_CASE(VK_ERROR_LAYER_NOT_PRESENT)
    SDFC_VK_RESULT_CASE(VK_ERROR_EXTENSION_NOT_PRESENT)
    SDFC_VK_RESULT_CASE(VK_ERROR_FEATURE_NOT_PRESENT)
    SDFC_VK_RESULT_CASE(VK_ERROR_INCOMPATIBLE_DRIVER)
    SDFC_VK_RESULT_CASE(VK_ERROR_TOO_MANY_OBJECTS)
    SDFC_VK_RESULT_CASE(VK_ERROR_FORMAT_NOT_SUPPORTED)
    SDFC_VK_RESULT_CASE(VK_ERROR_FRAGMENTED_POOL)
    SDFC_VK_RESULT_CASE(VK_ERROR_UNKNOWN)
    SDFC_VK_RESULT_CASE(VK_ERROR_OUT_OF_POOL_MEMORY)
    SDFC_VK_RESULT_CASE(VK_ERROR_INVALID_EXTERNAL_HANDLE)
    SDFC_VK_RESULT_CASE(VK_ERROR_FRAGMENTATION)
    SDFC_VK_RESULT_CASE(VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS)
    SDFC_VK_RESULT_CASE(VK_PIPELINE_COMPILE_REQUIRED)
    SDFC_VK_RESULT_CASE(VK_ERROR_SURFACE_LOST_KHR)
    SDFC_VK_RESULT_CASE(VK_ERROR_NATIVE_WINDOW_IN_USE_KHR)
    SDFC_VK_RESULT_CASE(VK_SUBOPTIMAL_KHR)
    SDFC_VK_RESULT_CASE(VK_ERROR_OUT_OF_DATE_KHR)
    SDFC_VK_RESULT_CASE(VK_ERROR_VALIDATION_FAILED_EXT)
    SDFC_VK_RESULT_CASE(VK_ERROR_INVALID_SHADER_NV)
#undef SDFC_VK_RESULT_CASE
    default:
      break;
  }
  // Unknown codes: a static buffer per thread keeps the const char* contract simple.
  thread_local std::string unknown;
  unknown = "VkResult(" + std::to_string(static_cast<int>(result)) + ")";
  return unknown.c_str();
}

void throwVkError(VkResult result, const char* call, const char* file, int line) {
  const std::string where = std::filesystem::path(file).filename().string();
  throw RuntimeError(where + ":" + std::to_string(line) + ": " + call + " failed with " +
                     vkResultName(result));
}

}  // namespace sdfc
