#include "check_runner.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace asval::fuzz {

namespace {

void Require(bool ok, const char* property, const char* detail) {
  if (ok) return;
  std::fprintf(stderr, "fuzz property violated: %s (%s)\n", property, detail ? detail : "");
  std::abort();
}

bool StartsWith(const char* text, const char* prefix) {
  const size_t n = std::strlen(prefix);
  return std::strncmp(text, prefix, n) == 0 && text[n] != '\0';
}

ReportSettings EveryMessage() {
  ReportSettings settings;
  settings.report_info = true;
  settings.duplicate_message_limit = 0;  // unlimited: the second run must see the same messages
  return settings;
}

}  // namespace

CheckRunner::CheckRunner(const DeviceState& state, uint32_t families, bool skip_answer)
    : state_(state), reporter_(EveryMessage()), families_(families), skip_answer_(skip_answer) {
  VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT |
                         VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                         VK_DEBUG_UTILS_MESSAGE_SEVERITY_INFO_BIT_EXT |
                         VK_DEBUG_UTILS_MESSAGE_SEVERITY_VERBOSE_BIT_EXT;
  info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                     VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  info.pfnUserCallback = &CheckRunner::Receive;
  info.pUserData = this;
  reporter_.AddMessenger(reinterpret_cast<VkDebugUtilsMessengerEXT>(uint64_t{0x1}), info);
}

VKAPI_ATTR VkBool32 VKAPI_CALL CheckRunner::Receive(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                    VkDebugUtilsMessageTypeFlagsEXT,
                                                    const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  auto* self = static_cast<CheckRunner*>(user);
  Require(data != nullptr && data->sType == VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CALLBACK_DATA_EXT,
          "callback data", nullptr);
  const char* id = data->pMessageIdName;
  Require(id != nullptr, "a message id", nullptr);
  Require(StartsWith(id, "VUID-") || StartsWith(id, "ASVAL-"), "message id is VUID-... or ASVAL-...", id);
  Require(data->pMessage != nullptr && data->pMessage[0] != '\0', "non-empty message text", id);
  Require(severity != 0 && (severity & (severity - 1)) == 0, "one severity bit", id);
  Require(data->objectCount == 0 || data->pObjects != nullptr, "objects readable", id);
  for (uint32_t k = 0; k < data->objectCount; ++k) {
    Require(data->pObjects[k].sType == VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT, "object name info", id);
  }
  self->messages_.ids.push_back(id);
  self->messages_.texts.push_back(data->pMessage);
  return self->skip_answer_ ? VK_TRUE : VK_FALSE;
}

bool CheckRunner::Run(const std::function<bool(const CheckContext&)>& check, uint32_t without) {
  const CheckContext ctx{state_, reporter_, families_ & ~without};
  // The first run may fill the per-thread memos and the size cache; the next two must agree with each other.
  // (Not with the first: the open finding in check_runner.h.)
  messages_ = Messages{};
  const bool skip = check(ctx);
  messages_ = Messages{};
  const bool skip_warm = check(ctx);
  const Messages warm = std::move(messages_);
  messages_ = Messages{};
  const bool skip_again = check(ctx);
  if (warm.texts != messages_.texts) {
    for (const std::string& text : warm.texts) std::fprintf(stderr, "run 2: %s\n", text.c_str());
    for (const std::string& text : messages_.texts) std::fprintf(stderr, "run 3: %s\n", text.c_str());
  }
  Require(warm.ids == messages_.ids, "the same message ids on the same call", nullptr);
  Require(warm.texts == messages_.texts, "the same message texts on the same call", nullptr);
  Require(skip_warm == skip_again, "the same skip answer on the same call", nullptr);
  return skip;
}

}  // namespace asval::fuzz
