#pragma once
// Helpers for the tests of the addresses, aliasing and host families: buffers and structures placed by hand
// in one VkDeviceMemory (as sub-allocators do), the driver's sizes for a build, and one-call recording of
// any number of infos.
#include <vector>

#include "fixture.h"
#include "record_checks_helpers.h"

namespace asval_test {

// One host-visible VkDeviceMemory (allocated with DEVICE_ADDRESS) that buffers are bound into at chosen
// offsets. Everything bound here is destroyed with it.
class SharedMemory {
 public:
  SharedMemory(vkkit::Device& device, VkDeviceSize size);
  ~SharedMemory();
  SharedMemory(const SharedMemory&) = delete;
  SharedMemory& operator=(const SharedMemory&) = delete;

  // A buffer of `size` bytes bound at `offset` (a multiple of 256 keeps every usage's alignment); usage gets
  // SHADER_DEVICE_ADDRESS added. mapped points at the buffer's first byte.
  vkkit::Buffer Bind(VkDeviceSize offset, VkDeviceSize size, VkBufferUsageFlags usage);
  // An acceleration structure of `size` bytes at `offset` of `buffer` (a multiple of 256).
  VkAccelerationStructureKHR Structure(const vkkit::Buffer& buffer, VkDeviceSize offset, VkDeviceSize size,
                                       VkAccelerationStructureTypeKHR type);
  void DestroyBuffer(vkkit::Buffer& buffer);  // early, e.g. to reuse its addresses
  void DestroyStructure(VkAccelerationStructureKHR structure);  // early, before its buffer
  VkDeviceMemory memory() const { return memory_; }

 private:
  vkkit::Device& device_;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  void* mapped_ = nullptr;
  std::vector<VkBuffer> buffers_;
  std::vector<VkAccelerationStructureKHR> structures_;
};

// What the driver reports for a build of `info` with these primitive counts.
VkAccelerationStructureBuildSizesInfoKHR DriverSizes(vkkit::Device& device,
                                                     const VkAccelerationStructureBuildGeometryInfoKHR& info,
                                                     const std::vector<uint32_t>& counts);

// Rounds up to a multiple of `unit`.
inline VkDeviceSize RoundUp(VkDeviceSize value, VkDeviceSize unit) { return (value + unit - 1) / unit * unit; }

// Records one vkCmdBuildAccelerationStructuresIndirectKHR of `infos` into a command buffer that is never
// submitted. Lavapipe has no indirect builds: only calls the layer skips (an expected finding) may be made.
void RecordIndirect(vkkit::Device& device, const std::vector<VkAccelerationStructureBuildGeometryInfoKHR>& infos,
                    const std::vector<VkDeviceAddress>& addresses, const std::vector<uint32_t>& strides,
                    const std::vector<std::vector<uint32_t>>& max_counts);
// Calls vkBuildAccelerationStructuresKHR (no deferred operation). Lavapipe has no host builds: the same
// restriction applies.
VkResult CallHostBuild(vkkit::Device& device, const std::vector<VkAccelerationStructureBuildGeometryInfoKHR>& infos,
                       const std::vector<const VkAccelerationStructureBuildRangeInfoKHR*>& ranges,
                       VkDeferredOperationKHR deferred = VK_NULL_HANDLE);

// Records (device commands; never submitted) or calls (host) one build of `infos`, like Issue(), but an
// indirect build reads its ranges from a real INDIRECT_BUFFER holding `ranges` (stride 16), so that only the
// rule under test is broken.
void IssueWithRealRanges(vkkit::Device& device, Command command,
                         const std::vector<VkAccelerationStructureBuildGeometryInfoKHR>& infos,
                         const std::vector<const VkAccelerationStructureBuildRangeInfoKHR*>& ranges);

// A pipeline barrier from acceleration-structure build writes to build reads (build, then update).
void BuildBarrier(VkCommandBuffer cb);

}  // namespace asval_test
