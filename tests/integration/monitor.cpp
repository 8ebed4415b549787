#include "monitor.h"

#include <algorithm>

namespace asval_test {

Monitor::Monitor() {
  create_info_.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
  // Errors and warnings: informational chatter (the loader's, the Khronos layer's status lines in
  // self-validation runs) is not what tests assert on.
  create_info_.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT |
                                 VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT;
  create_info_.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                             VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  create_info_.pfnUserCallback = &Monitor::Callback;
  create_info_.pUserData = this;
}

void Monitor::Expect(const std::string& vuid, int count) {
  std::lock_guard lock(mutex_);
  expected_.emplace_back(vuid, count);
}

VKAPI_ATTR VkBool32 VKAPI_CALL Monitor::Callback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                 VkDebugUtilsMessageTypeFlagsEXT,
                                                 const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  auto* self = static_cast<Monitor*>(user);
  Message m;
  m.severity = severity;
  m.id_name = data->pMessageIdName ? data->pMessageIdName : "";
  m.id_number = data->messageIdNumber;
  m.text = data->pMessage ? data->pMessage : "";
  for (uint32_t i = 0; i < data->objectCount; ++i) {
    m.objects.push_back(data->pObjects[i]);
    m.objects.back().pObjectName = nullptr;  // the callback data dies with the call: see names
    m.names.push_back(data->pObjects[i].pObjectName ? data->pObjects[i].pObjectName : "");
  }
  std::lock_guard lock(self->mutex_);
  for (const std::string& prefix : self->ignored_) {
    if (m.id_name.rfind(prefix, 0) == 0) return VK_FALSE;
  }
  // Only messages of interest to a test reach here: informational loader chatter has no VUID.
  if (severity < VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT && m.id_name.empty()) return VK_FALSE;
  const bool expected = std::any_of(self->expected_.begin(), self->expected_.end(),
                                    [&](const auto& e) { return e.first == m.id_name; });
  self->received_.push_back(std::move(m));
  return expected ? VK_TRUE : VK_FALSE;
}

std::string Monitor::Verify() {
  std::lock_guard lock(mutex_);
  std::string problems;
  std::vector<bool> used(received_.size(), false);
  for (const auto& [vuid, count] : expected_) {
    int seen = 0;
    for (size_t i = 0; i < received_.size(); ++i) {
      if (received_[i].id_name == vuid) {
        ++seen;
        used[i] = true;
      }
    }
    if (seen != count) {
      problems += "expected " + std::to_string(count) + " x " + vuid + ", got " + std::to_string(seen) + "\n";
    }
  }
  for (size_t i = 0; i < received_.size(); ++i) {
    if (!used[i]) problems += "unexpected message: " + received_[i].text + "\n";
  }
  expected_.clear();
  received_.clear();
  return problems;
}

std::vector<Message> Monitor::Take() {
  std::lock_guard lock(mutex_);
  std::vector<Message> out = std::move(received_);
  received_.clear();
  expected_.clear();
  return out;
}

}  // namespace asval_test
