#pragma once
// Runs one const check of the layer over a synthetic device's state and a Reporter whose messenger verifies each
// message as it arrives: a message id that is a VUID ("VUID-...") or a layer id ("ASVAL-..."), non-empty text,
// one severity, readable objects. Any violation aborts (a fuzz finding). Each check runs three times: the third
// run must report exactly what the second did (memos and caches, once filled, must not change an answer).
//
// Not asserted, an open finding (issue 14, fuzz-checks report): the first run of a call may report less than the
// second. The size cache answers an info whose own size query the layer would not make (a wrong sType in the
// info or a geometry, say: SizeQueryIsValid) when an info of the same signature was queried before, so the size
// rules (pInfos-10126, 12261, ...) judge such an info only after another with the same shape was seen.
#include <functional>
#include <string>
#include <vector>

#include "check_context.h"

namespace asval::fuzz {

class CheckRunner {
 public:
  // families: LayerSettingFlagBits kCheck*; skip_answer: what the app's callback returns (VK_TRUE asks to skip).
  CheckRunner(const DeviceState& state, uint32_t families, bool skip_answer);
  CheckRunner(const CheckRunner&) = delete;
  CheckRunner& operator=(const CheckRunner&) = delete;

  // Whether the check asked that the call be skipped. `without`: families left out of this run.
  bool Run(const std::function<bool(const CheckContext&)>& check, uint32_t without = 0);
  uint32_t families() const { return families_; }

 private:
  struct Messages {
    std::vector<std::string> ids;
    std::vector<std::string> texts;
  };
  static VKAPI_ATTR VkBool32 VKAPI_CALL Receive(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                VkDebugUtilsMessageTypeFlagsEXT types,
                                                const VkDebugUtilsMessengerCallbackDataEXT* data, void* user);

  const DeviceState& state_;
  Reporter reporter_;
  uint32_t families_;
  bool skip_answer_;
  Messages messages_;
};

}  // namespace asval::fuzz
