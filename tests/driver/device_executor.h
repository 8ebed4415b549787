#pragma once
// Runs the test driver's own work on the device below it: one command buffer at a time, recorded, submitted on
// the application's queue (under the queue's lock) and waited for; and host-visible staging buffers with device
// addresses, where host inputs are copied for a device build and device results read back.
#include <vulkan/vulkan.h>

#include <functional>
#include <mutex>

namespace asval_test_driver {

struct DeviceData;

struct StagingBuffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  unsigned char* mapped = nullptr;
  VkDeviceAddress address = 0;
  VkDeviceSize size = 0;
};

class DeviceExecutor {
 public:
  explicit DeviceExecutor(DeviceData& device);
  ~DeviceExecutor();
  DeviceExecutor(const DeviceExecutor&) = delete;
  DeviceExecutor& operator=(const DeviceExecutor&) = delete;

  // A buffer of at least `bytes`, mapped, with a device address usable as build input, scratch and copy target.
  VkResult CreateStaging(VkDeviceSize bytes, StagingBuffer* out);
  void DestroyStaging(StagingBuffer* buffer);

  // Records `record` into the driver's command buffer, submits it and waits for it. `queue_locked`: the caller
  // holds the device's queue lock already (the test driver's submission hooks).
  VkResult Run(const std::function<void(VkCommandBuffer)>& record, bool queue_locked = false);

 private:
  VkResult Prepare();  // the pool, command buffer and fence, at first use

  DeviceData& device_;
  std::mutex lock_;  // one Run at a time: one command buffer
  VkQueue queue_ = VK_NULL_HANDLE;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer command_buffer_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
};

}  // namespace asval_test_driver
