#pragma once
// VK_NV_ray_tracing programs for the tests (on the test driver, which implements the extension: tests/driver): the
// NV commands loaded through the loader, and structures created with their VkAccelerationStructureInfoNV, bound to
// memory of their own (or to another structure's) as vkGetAccelerationStructureMemoryRequirementsNV asks.
#include <vulkan/vulkan.h>

#include <functional>
#include <optional>
#include <vector>

#include "history_helpers.h"
#include "on_test_driver.h"
#include "vkkit.h"

namespace asval_test {

// Where the NV tests run: on the test driver, which implements VK_NV_ray_tracing over a driver without it, unless
// ASVAL_TEST_NV_NATIVE=1 says the driver below has the extension itself (an NVIDIA GPU: scripts/device_integration.sh).
// Declare one before the fixture, as OnTestDriver.
class NvDriver {
 public:
  NvDriver();

 private:
  std::optional<OnTestDriver> test_driver_;
};

// The device options of a program that enables VK_NV_ray_tracing.
vkkit::DeviceOptions NvRayTracing();

struct NvProcs {
  explicit NvProcs(VkDevice device);
  PFN_vkCreateAccelerationStructureNV Create = nullptr;
  PFN_vkDestroyAccelerationStructureNV Destroy = nullptr;
  PFN_vkGetAccelerationStructureMemoryRequirementsNV Requirements = nullptr;
  PFN_vkBindAccelerationStructureMemoryNV Bind = nullptr;
  PFN_vkGetAccelerationStructureHandleNV Handle = nullptr;
  PFN_vkCmdBuildAccelerationStructureNV CmdBuild = nullptr;
  PFN_vkCmdCopyAccelerationStructureNV CmdCopy = nullptr;
  PFN_vkCmdWriteAccelerationStructuresPropertiesNV CmdWriteProperties = nullptr;
};

// Geometry inputs in one buffer created with VK_BUFFER_USAGE_RAY_TRACING_BIT_NV: 16 vertices (R32G32B32_SFLOAT),
// 6 indices (uint32), 2 AABBs.
class NvInputs {
 public:
  explicit NvInputs(vkkit::Device& device);
  ~NvInputs();
  NvInputs(const NvInputs&) = delete;
  NvInputs& operator=(const NvInputs&) = delete;
  // `triangles` triangles, indexed or not.
  VkGeometryNV Triangles(uint32_t triangles, bool indexed = false) const;
  VkGeometryNV Aabbs(uint32_t count) const;
  VkBuffer buffer() const { return buffer_.buffer; }

 private:
  vkkit::Device& device_;
  vkkit::Buffer buffer_;
};

// A structure created with `geometries` (bottom level) or `instances` (top level) and `flags`, bound to memory of its
// own (or, with `share`, to share's memory at its offset: the two alias), or left unbound.
class NvStructure {
 public:
  enum class Memory { kOwn, kUnbound };
  NvStructure(vkkit::Device& device, VkBuildAccelerationStructureFlagsNV flags, std::vector<VkGeometryNV> geometries,
              Memory memory = Memory::kOwn, const NvStructure* share = nullptr);
  // A top level of `instances` instances.
  NvStructure(vkkit::Device& device, VkBuildAccelerationStructureFlagsNV flags, uint32_t instances);
  ~NvStructure();
  NvStructure(const NvStructure&) = delete;
  NvStructure& operator=(const NvStructure&) = delete;

  VkAccelerationStructureNV handle() const { return handle_; }
  // The creation info (pGeometries points into this object).
  const VkAccelerationStructureInfoNV& info() const { return info_; }
  VkDeviceSize Requirement(VkAccelerationStructureMemoryRequirementsTypeNV type) const;
  // The 8 bytes vkGetAccelerationStructureHandleNV writes (instances reference it).
  uint64_t Reference() const;
  // An instance of this structure (VkAccelerationStructureInstanceNV): identity transform moved 4 units along X per
  // index `i`, mask 0xff.
  VkAccelerationStructureInstanceNV Instance(uint32_t i) const;

 private:
  void Create(Memory memory, const NvStructure* share);

  vkkit::Device& device_;
  NvProcs procs_;
  std::vector<VkGeometryNV> geometries_;
  VkAccelerationStructureInfoNV info_{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_INFO_NV};
  VkAccelerationStructureNV handle_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;  // own memory
  VkDeviceMemory bound_ = VK_NULL_HANDLE;   // what it is bound to (own or shared)
};

// A buffer created with `usage` (VK_BUFFER_USAGE_RAY_TRACING_BIT_NV for scratch and instances), of `size` bytes.
vkkit::Buffer NvBuffer(vkkit::Device& device, VkDeviceSize size,
                       VkBufferUsageFlags usage = VK_BUFFER_USAGE_RAY_TRACING_BIT_NV);

// Records `record` into a new command buffer of `commands` and submits it alone (waiting for the queue when the
// layer let it through); the layer's result.
VkResult RunCommands(Commands& commands, const std::function<void(VkCommandBuffer)>& record);
// The same with a pool of its own.
VkResult RunCommands(vkkit::Device& device, const std::function<void(Commands&, VkCommandBuffer)>& record);

// vkCmdBuildAccelerationStructureNV of dst with dst's own creation info (or `info`), from src when updating.
void CmdBuildNV(vkkit::Device& device, VkCommandBuffer cb, const NvStructure& dst, VkBuffer scratch,
                bool update = false, const NvStructure* src = nullptr,
                const VkAccelerationStructureInfoNV* info = nullptr, VkBuffer instance_data = VK_NULL_HANDLE);

}  // namespace asval_test
