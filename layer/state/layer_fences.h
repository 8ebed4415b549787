#pragma once
// The layer's own fences, passed down with a submission the app gave none so that the layer learns when it completed
// (the capture tracker's and the in-flight set's): taken from a spare list, else created; a failure (or the test hook
// ASVAL_TEST_FAIL=inserted_fence) gives VK_NULL_HANDLE, and the caller goes on without one.
#include <vulkan/vulkan.h>

#include <mutex>
#include <vector>

#include "failure_injection.h"
#include "vk_dispatch_table.h"

namespace asval {

// `spare` is guarded by `mutex`.
inline VkFence TakeLayerFence(VkDevice device, const DeviceDispatchTable& next, std::mutex& mutex,
                              std::vector<VkFence>& spare) {
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (!spare.empty()) {
      VkFence f = spare.back();
      spare.pop_back();
      return f;
    }
  }
  VkFenceCreateInfo info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence fence = VK_NULL_HANDLE;
  if (InjectedFailure(FailSite::kLayerFence)) return VK_NULL_HANDLE;  // the test hook: as if vkCreateFence failed
  if (!next.CreateFence || next.CreateFence(device, &info, nullptr, &fence) != VK_SUCCESS) return VK_NULL_HANDLE;
  return fence;
}

}  // namespace asval
