#include "deferred_operations.h"

#include <utility>

namespace asval_test_driver {

VkResult DeferredOperations::Defer(VkDeferredOperationKHR operation, std::function<VkResult()> work) {
  std::lock_guard<std::mutex> lock(lock_);
  entries_[operation] = Entry{std::move(work), VK_NOT_READY};
  return VK_OPERATION_DEFERRED_KHR;
}

VkResult DeferredOperations::Join(VkDeferredOperationKHR operation) {
  std::function<VkResult()> work;
  {
    std::lock_guard<std::mutex> lock(lock_);
    const auto it = entries_.find(operation);
    if (it == entries_.end() || !it->second.work) return VK_THREAD_DONE_KHR;
    work = std::move(it->second.work);
    it->second.work = nullptr;
  }
  const VkResult result = work();
  std::lock_guard<std::mutex> lock(lock_);
  const auto it = entries_.find(operation);
  if (it != entries_.end()) it->second.result = result;
  return VK_SUCCESS;
}

VkResult DeferredOperations::Result(VkDeferredOperationKHR operation) {
  std::lock_guard<std::mutex> lock(lock_);
  const auto it = entries_.find(operation);
  return it == entries_.end() ? VK_SUCCESS : it->second.result;
}

void DeferredOperations::Forget(VkDeferredOperationKHR operation) {
  std::lock_guard<std::mutex> lock(lock_);
  entries_.erase(operation);
}

}  // namespace asval_test_driver
