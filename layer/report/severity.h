#pragma once
// Severity of a finding, and how it maps onto VK_EXT_debug_utils.
#include <vulkan/vulkan.h>

#include <cstdint>

namespace asval {

enum class Severity : uint8_t { kError, kWarning, kInfo };

inline VkDebugUtilsMessageSeverityFlagBitsEXT ToDebugUtilsSeverity(Severity s) {
  switch (s) {
    case Severity::kError: return VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    case Severity::kWarning: return VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT;
    case Severity::kInfo: break;
  }
  return VK_DEBUG_UTILS_MESSAGE_SEVERITY_INFO_BIT_EXT;
}

inline const char* SeverityName(Severity s) {
  switch (s) {
    case Severity::kError: return "error";
    case Severity::kWarning: return "warning";
    case Severity::kInfo: break;
  }
  return "info";
}

// The heading of the text message, as the Khronos layer writes it.
inline const char* SeverityHeading(Severity s) {
  switch (s) {
    case Severity::kError: return "Validation Error";
    case Severity::kWarning: return "Validation Warning";
    case Severity::kInfo: break;
  }
  return "Validation Information";
}

}  // namespace asval
