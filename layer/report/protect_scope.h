#pragma once
// Protect mode (setting `protect`) keeps from the driver every call for which the layer reports an error. The hook
// that may withhold a call opens a ProtectScope around the call's validation; the reporter notes in it the first
// error it acts on (Reporter::Report), so that the hook can name that finding when it withholds the call and tell a
// protected call from one the app's callback asked to skip (VK_TRUE), which is not marked or announced.
//
// One scope per thread is current; scopes nest (an app callback that calls Vulkan from inside a report opens its
// own, and the outer one is current again when it closes). A scope opened with protect mode off is inert and
// touches no thread-local storage (the hooks' one thread-local access is CheckThreadLease's); an active one costs
// two thread-local stores, and no allocation until an error is noted.
#include <string>
#include <string_view>

#include "location.h"

namespace asval {

class ProtectScope {
 public:
  // `active`: protect mode is on (Reporter::protects()).
  explicit ProtectScope(bool active);
  ~ProtectScope();
  ProtectScope(const ProtectScope&) = delete;
  ProtectScope& operator=(const ProtectScope&) = delete;

  // Protect mode acted on an error reported while this scope was current: the call must not reach the driver.
  bool withheld() const { return withheld_; }
  // The first such error: its VUID (newest spelling) and where ("vkCmdBuildAccelerationStructuresKHR():
  // pInfos[0].scratchData"). Empty when the text could not be kept (allocation failure): still withheld.
  const std::string& vuid() const { return vuid_; }
  const std::string& where() const { return where_; }
  // The command the error is about, e.g. "vkCmdBuildAccelerationStructuresKHR" (its Location's root); "" before.
  const char* function() const { return function_; }

  // The reporter's side: an error protect mode acts on. The first is kept by the current scope; without one (a
  // report outside any protecting hook) nothing is kept. May throw std::bad_alloc after marking the scope.
  static void NoteError(std::string_view vuid, const Location& loc);

 private:
  const bool active_;
  ProtectScope* outer_ = nullptr;
  bool withheld_ = false;
  const char* function_ = "";
  std::string vuid_;
  std::string where_;
};

}  // namespace asval
