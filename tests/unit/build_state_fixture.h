#pragma once
// A device's shadow state built by hand, without a driver, for the build-command rules that lavapipe cannot
// run (host and indirect builds, memory that is not host-visible, device groups): the state tracker records
// fake objects, a fake size query stands in for vkGetAccelerationStructureBuildSizesKHR, and a messenger
// collects what the reporter delivers.
#include <vulkan/vulkan.h>

#include <string>
#include <vector>

#include "build_command.h"
#include "check_context.h"
#include "device_state.h"
#include "reporter.h"

namespace asval {

// The fake driver's sizes: accelerationStructureSize = 256 + 64 x (sum of counts), buildScratchSize =
// 128 + 16 x (sum of counts), updateScratchSize = kUpdateScratch (0 when update_scratch_zero is set).
struct FakeSizes {
  static constexpr VkDeviceSize kUpdateScratch = 64;
  static VkDeviceSize Structure(uint64_t primitives) { return 256 + 64 * primitives; }
  static VkDeviceSize BuildScratch(uint64_t primitives) { return 128 + 16 * primitives; }
  static inline bool update_scratch_zero = false;
  static inline int queries = 0;
};

class BuildStateFixture {
 public:
  // Memory types: 0 host-visible (heap 0), 1 device-local only (heap 0), 2 host-visible on a MULTI_INSTANCE
  // heap (heap 1). The device enables accelerationStructure, host commands, indirect builds, rayQuery.
  BuildStateFixture();

  // A VkDeviceMemory of `size` bytes of memory type `type`, allocated with DEVICE_ADDRESS; device_mask != 0
  // adds VK_MEMORY_ALLOCATE_DEVICE_MASK_BIT with that mask.
  VkDeviceMemory Memory(VkDeviceSize size, uint32_t type = 0, uint32_t device_mask = 0);
  // A buffer with SHADER_DEVICE_ADDRESS added to `usage`, bound at `offset` of `memory`. Its device address
  // is the buffer's handle value x 0x10000 (as the fake dispatch answers), so buffers never share addresses.
  VkBuffer Buffer(VkDeviceSize size, VkBufferUsageFlags usage, VkDeviceMemory memory, VkDeviceSize offset = 0);
  VkDeviceAddress AddressOf(VkBuffer buffer) const;
  VkAccelerationStructureKHR Structure(VkBuffer buffer, VkDeviceSize offset, VkDeviceSize size,
                                       VkAccelerationStructureTypeKHR type);
  void DestroyStructure(VkAccelerationStructureKHR as);

  // Runs the addresses, aliasing and host families over `cmd` (all enabled). Returns the skip flag.
  bool Validate(const BuildCommand& cmd);
  // The VUIDs reported since the last call, in order.
  std::vector<std::string> Take();

  DeviceState state;
  Reporter reporter{ReportSettings{}};
  std::vector<std::string> ids;
  std::vector<std::string> texts;

 private:
  uint64_t next_handle_ = 0x100;
};

// A host build (no deferred operation) / an indirect build over caller-owned arrays.
BuildCommand HostBuild(uint32_t count, const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                       const VkAccelerationStructureBuildRangeInfoKHR* const* ranges);
BuildCommand IndirectBuild(uint32_t count, const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                           const VkDeviceAddress* addresses, const uint32_t* strides, const uint32_t* const* max_counts);

// A one-triangle geometry (R32G32B32_SFLOAT, stride 12, maxVertex 2) whose data is at `vertices` (a device
// address or a host pointer's bits).
VkAccelerationStructureGeometryKHR TriangleGeometry(uint64_t vertices);
// An instance geometry whose data is at `instances`.
VkAccelerationStructureGeometryKHR InstanceGeometry(uint64_t instances);
// A BUILD-mode info of `type` over one geometry.
VkAccelerationStructureBuildGeometryInfoKHR OneGeometryInfo(VkAccelerationStructureTypeKHR type,
                                                            const VkAccelerationStructureGeometryKHR* geometry);

}  // namespace asval
