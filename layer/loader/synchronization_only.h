#pragma once
// What goes down in place of a submission protect mode withholds (withhold.h): its batches without their command
// buffers, with the same semaphore waits (and their stage masks), signals, chained semaphore values and fence. So
// whatever the app or the device waits for still completes (the host on the fence or a timeline value, a later
// submission or a present on a semaphore, another queue on a timeline value), and nothing the app recorded runs.
// docs/protect.md ("What the app sees") says why that is safe.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

namespace asval {

// The batches of one vkQueueSubmit call, emptied. A batch keeps the app's pNext chain, except one that holds a
// VkDeviceGroupSubmitInfo, whose commandBufferCount must match the batch's: its chain is rebuilt from copies of the
// structures that still mean something without command buffers (device group with no command buffers, timeline
// values, protected submission, performance query pass); others are dropped. Throws std::bad_alloc.
class EmptiedSubmits {
 public:
  EmptiedSubmits(uint32_t count, const VkSubmitInfo* submits);
  EmptiedSubmits(const EmptiedSubmits&) = delete;
  EmptiedSubmits& operator=(const EmptiedSubmits&) = delete;

  uint32_t count() const { return static_cast<uint32_t>(submits_.size()); }
  const VkSubmitInfo* submits() const { return submits_.empty() ? nullptr : submits_.data(); }

 private:
  // The copies one batch's rebuilt chain links (only the ones it had are linked).
  struct Chain {
    VkDeviceGroupSubmitInfo device_group{};
    VkTimelineSemaphoreSubmitInfo timeline{};
    VkProtectedSubmitInfo protected_submit{};
    VkPerformanceQuerySubmitInfoKHR performance_query{};
  };
  const void* RebuiltChain(const void* next, Chain& chain);

  std::vector<VkSubmitInfo> submits_;
  std::vector<Chain> chains_;  // sized once, before any pointer into it is taken
};

// The batches of one vkQueueSubmit2 call, emptied: nothing in VkSubmitInfo2's chain depends on its command buffers,
// so each keeps the app's. Throws std::bad_alloc.
class EmptiedSubmits2 {
 public:
  EmptiedSubmits2(uint32_t count, const VkSubmitInfo2* submits);

  uint32_t count() const { return static_cast<uint32_t>(submits_.size()); }
  const VkSubmitInfo2* submits() const { return submits_.empty() ? nullptr : submits_.data(); }

 private:
  std::vector<VkSubmitInfo2> submits_;
};

}  // namespace asval
