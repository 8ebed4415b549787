#pragma once
// vkCmdBuildAccelerationStructuresIndirectKHR on a driver without it. The command is recorded as
// vkCmdExecuteCommands of a secondary command buffer of the test driver's; when a submission holding it reaches the
// test driver, the queue is drained, the range infos are read from the memory the indirect addresses name (a copy
// by the driver below), and the secondary is recorded with the direct build of those ranges. So the build reads its
// ranges as they are when the submission is made: written by the host or by earlier submissions. (Commands of the
// same submission that write them before the build are not seen: docs/testing.md.)
#include <vulkan/vulkan.h>

#include <mutex>
#include <unordered_map>
#include <vector>

namespace asval_test_driver {

struct DeviceData;

class IndirectBuilds {
 public:
  explicit IndirectBuilds(DeviceData& device);
  ~IndirectBuilds();
  IndirectBuilds(const IndirectBuilds&) = delete;
  IndirectBuilds& operator=(const IndirectBuilds&) = delete;

  // vkBeginCommandBuffer: a command buffer recorded again forgets its indirect builds.
  void Begin(VkCommandBuffer command_buffer);
  void Record(VkCommandBuffer command_buffer, uint32_t info_count,
              const VkAccelerationStructureBuildGeometryInfoKHR* infos, const VkDeviceAddress* addresses,
              const uint32_t* strides, const uint32_t* const* max_counts);
  // Called with the queue's lock held, before the submission of `command_buffers` goes down: records the
  // secondaries of their indirect builds from the ranges in memory now.
  VkResult Prepare(VkQueue queue, const std::vector<VkCommandBuffer>& command_buffers);

 private:
  struct Build {  // one info of an indirect command, deep-copied at record time
    VkAccelerationStructureBuildGeometryInfoKHR info{};
    std::vector<VkAccelerationStructureGeometryKHR> geometries;
    std::vector<uint32_t> max_counts;
    VkDeviceAddress address = 0;
    uint32_t stride = 0;
  };
  struct Site {  // one indirect command
    VkCommandBuffer secondary = VK_NULL_HANDLE;
    std::vector<Build> builds;
  };
  VkResult RecordSecondary(const Site& site, std::vector<std::vector<VkAccelerationStructureBuildRangeInfoKHR>> ranges);

  DeviceData& device_;
  std::mutex lock_;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  std::unordered_map<VkCommandBuffer, std::vector<Site>> sites_;
};

}  // namespace asval_test_driver
