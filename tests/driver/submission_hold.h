#pragma once
// Test-only entry point of the test driver: holding the device's submissions pending without the layers above
// knowing why (tests of work in flight whose batches asval must see applied at once, not deferred behind a wait
// it can see). While held, every submission's first batch also waits for a timeline semaphore of the test driver's,
// which the release signals. Needs the timelineSemaphore feature enabled.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

#include "test_driver_api.h"

namespace asval_test_driver {

struct DeviceData;

class SubmissionHold {
 public:
  // Called under the queue lock.
  VkResult Hold(DeviceData& device, bool hold);
  // The batches to pass down in place of submits[0..count): `submits` itself when not held. Kept in this object:
  // valid until the next call.
  const VkSubmitInfo* Submits(uint32_t count, const VkSubmitInfo* submits);
  const VkSubmitInfo2* Submits2(uint32_t count, const VkSubmitInfo2* submits);
  // vkDestroyDevice.
  void Destroy(DeviceData& device);

 private:
  VkSemaphore semaphore_ = VK_NULL_HANDLE;
  uint64_t value_ = 0;  // the value a held submission waits for
  bool held_ = false;
  std::vector<VkSubmitInfo> submits_;
  std::vector<VkSubmitInfo2> submits2_;
  std::vector<VkSemaphore> waits_;
  std::vector<VkPipelineStageFlags> stages_;
  std::vector<uint64_t> values_;
  std::vector<VkSemaphoreSubmitInfo> waits2_;
  VkTimelineSemaphoreSubmitInfo timeline_{VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO};
};

}  // namespace asval_test_driver
