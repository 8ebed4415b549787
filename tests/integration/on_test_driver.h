#pragma once
// Tests that need what no local driver has (host commands) run on asval's test driver (docs/testing.md): the
// layers the run names (ASVAL_TEST_LAYERS: asval alone, or asval over the Khronos layer), then the test driver,
// directly over lavapipe. Declare an OnTestDriver before the fixture.
#include <string>

#include "scoped_env.h"
#include "test_driver_api.h"
#include "vkkit.h"

namespace asval_test {

std::string LayersWithTestDriver();

class OnTestDriver {
 public:
  OnTestDriver() : layers_("ASVAL_TEST_LAYERS", LayersWithTestDriver()) {}

  // The device options of a program that enables accelerationStructureHostCommands.
  static vkkit::DeviceOptions HostCommands() {
    vkkit::DeviceOptions options;
    options.host_commands = true;
    return options;
  }

 private:
  ScopedEnvironment layers_;
};

// The test driver's held submissions (tests/driver/test_driver_api.h): work the layers above see submitted with no
// wait (asval applies it at once, as on a busy GPU), pending until Release. The device enables timelineSemaphore.
class HeldSubmissions {
 public:
  explicit HeldSubmissions(vkkit::Device& device);  // throws when the test driver is not below the layers
  ~HeldSubmissions();                               // releases what is still held
  HeldSubmissions(const HeldSubmissions&) = delete;
  HeldSubmissions& operator=(const HeldSubmissions&) = delete;

  // Submits `cb` (no semaphore, no fence), held pending.
  VkResult SubmitHeld(VkCommandBuffer cb);
  // Lets the held work run, and waits for the queue.
  VkResult Release();
  // Submits `cb` (no semaphore, no fence) and waits for the queue: it completed.
  VkResult SubmitAndWait(VkCommandBuffer cb);

 private:
  VkResult Submit(VkCommandBuffer cb);

  vkkit::Device& device_;
  PFN_vkAsvalTestDriverHoldSubmissions hold_ = nullptr;
  bool held_ = false;
};

// A structure on a buffer bound to device-local memory that is not host-visible (the test driver's added memory
// type: tests/driver/memory_types.h), where a discrete GPU keeps its structures; destroyed with the scope.
class DeviceLocalStructure {
 public:
  DeviceLocalStructure(vkkit::Device& device, VkAccelerationStructureTypeKHR type, VkDeviceSize size);
  ~DeviceLocalStructure();
  DeviceLocalStructure(const DeviceLocalStructure&) = delete;
  DeviceLocalStructure& operator=(const DeviceLocalStructure&) = delete;

  VkAccelerationStructureKHR handle() const { return structure_; }

 private:
  vkkit::Device& device_;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkAccelerationStructureKHR structure_ = VK_NULL_HANDLE;
};

}  // namespace asval_test
