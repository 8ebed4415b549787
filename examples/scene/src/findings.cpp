#include "findings.h"

#include <cstdio>

#include "gpu.h"

namespace scene {

VkDebugUtilsMessengerCreateInfoEXT Findings::CreateInfo(bool notices) {
  VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  if (notices) info.messageSeverity |= VK_DEBUG_UTILS_MESSAGE_SEVERITY_INFO_BIT_EXT;
  info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
  info.pfnUserCallback = &Findings::Callback;
  info.pUserData = this;
  return info;
}

void Findings::Attach(VkInstance instance, bool notices) {
  instance_ = instance;
  auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
      vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
  if (!create) return;  // no VK_EXT_debug_utils: layers print to stderr instead
  const VkDebugUtilsMessengerCreateInfoEXT info = CreateInfo(notices);
  Check(create(instance, &info, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
}

void Findings::Detach() {
  if (!messenger_) return;
  auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
      vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
  destroy(instance_, messenger_, nullptr);
  messenger_ = VK_NULL_HANDLE;
}

uint32_t Findings::errors() const {
  std::lock_guard lock(mutex_);
  return errors_;
}

uint32_t Findings::warnings() const {
  std::lock_guard lock(mutex_);
  return warnings_;
}

uint32_t Findings::infos() const {
  std::lock_guard lock(mutex_);
  return infos_;
}

uint32_t Findings::withheld_notices() const {
  std::lock_guard lock(mutex_);
  return withheld_notices_;
}

std::vector<Finding> Findings::all() const {
  std::lock_guard lock(mutex_);
  return all_;
}

VKAPI_ATTR VkBool32 VKAPI_CALL Findings::Callback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                  VkDebugUtilsMessageTypeFlagsEXT,
                                                  const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  auto* self = static_cast<Findings*>(user);
  Finding f;
  f.error = severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  f.info = severity < VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT;
  f.vuid = data->pMessageIdName ? data->pMessageIdName : "(no id)";
  f.message = data->pMessage ? data->pMessage : "";
  std::lock_guard lock(self->mutex_);
  if (f.info) {
    self->infos_ += 1;
    if (f.vuid == kWithheldNoticeId) self->withheld_notices_ += 1;
  } else {
    (f.error ? self->errors_ : self->warnings_) += 1;
  }
  std::printf("finding: %s %s\n%s\n", f.error ? "error" : f.info ? "info" : "warning", f.vuid.c_str(),
              f.message.c_str());
  std::fflush(stdout);  // keep the scene's own lines and the messages in order
  self->all_.push_back(std::move(f));
  // Never a skip: an application without a test framework lets every call through; protect mode decides.
  return VK_FALSE;
}

}  // namespace scene
