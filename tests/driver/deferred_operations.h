#pragma once
// Deferred host operations as a driver that really defers them: a host command given a deferred operation returns
// VK_OPERATION_DEFERRED_KHR and runs when the application joins the operation (one thread: the maximum
// concurrency is 1). The driver below creates and destroys the handles; the test driver keeps what is pending.
#include <vulkan/vulkan.h>

#include <functional>
#include <mutex>
#include <unordered_map>

namespace asval_test_driver {

class DeferredOperations {
 public:
  // Holds `work` for `operation`; what the command returns.
  VkResult Defer(VkDeferredOperationKHR operation, std::function<VkResult()> work);
  // vkDeferredOperationJoinKHR: runs the pending work (VK_SUCCESS), or VK_THREAD_DONE_KHR when nothing is left.
  VkResult Join(VkDeferredOperationKHR operation);
  // vkGetDeferredOperationResultKHR: VK_NOT_READY while pending, then the work's result (VK_SUCCESS for an
  // operation never used).
  VkResult Result(VkDeferredOperationKHR operation);
  void Forget(VkDeferredOperationKHR operation);

 private:
  struct Entry {
    std::function<VkResult()> work;  // empty once run
    VkResult result = VK_SUCCESS;
  };
  std::mutex lock_;
  std::unordered_map<VkDeferredOperationKHR, Entry> entries_;
};

}  // namespace asval_test_driver
