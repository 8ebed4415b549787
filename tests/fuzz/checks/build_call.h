#pragma once
// One build command decoded from fuzz input (vkCmdBuildAccelerationStructuresKHR, its indirect variant or the
// host vkBuildAccelerationStructuresKHR), owning every array its pointers reach: 0..N infos of any type, flags
// (bits newer than the headers too), mode and handles; geometry counts of 0, a few, or past maxGeometryCount with
// an array shorter than the count (the layer must not walk it); pGeometries, ppGeometries, both or neither;
// geometries of every type with formats, index types, strides and addresses inside, across and outside buffers;
// pNext chains of unknown structures and known ones in the wrong place; ranges or indirect arrays.
// Host builds point only into the device's HostArena, with room for everything the ranges say is read.
#include <vulkan/vulkan.h>

#include <memory>
#include <vector>

#include "build_command.h"
#include "byte_source.h"
#include "synthetic_device.h"

namespace asval::fuzz {

class BuildCall {
 public:
  BuildCall(ByteSource& in, SyntheticDevice& device, BuildCommandKind kind);
  BuildCall(const BuildCall&) = delete;
  BuildCall& operator=(const BuildCall&) = delete;

  const BuildCommand& command() const { return command_; }
  // Some info's geometry array is shorter than its count (a bottom-level info past maxGeometryCount).
  bool short_arrays() const { return short_arrays_; }

 private:
  // Arrays of exactly the length the command gives (a read past one is a sanitizer report).
  struct InfoArrays {
    std::vector<VkAccelerationStructureGeometryKHR> geometries;
    std::vector<const VkAccelerationStructureGeometryKHR*> pointers;
    std::vector<VkAccelerationStructureBuildRangeInfoKHR> ranges;
    std::vector<uint32_t> max_counts;
  };
  struct ChainNode {
    alignas(8) uint8_t bytes[256];
  };

  void DecodeInfo(ByteSource& in, uint32_t i);
  uint32_t DecodeGeometryCount(ByteSource& in, const VkAccelerationStructureBuildGeometryInfoKHR& info,
                               uint32_t* length);
  void DecodeGeometry(ByteSource& in, const VkAccelerationStructureBuildGeometryInfoKHR& info,
                      VkAccelerationStructureGeometryKHR& g, VkAccelerationStructureBuildRangeInfoKHR& range);
  void DecodeRange(ByteSource& in, VkAccelerationStructureBuildRangeInfoKHR& range);
  void PlaceHostInputs(ByteSource& in, const VkAccelerationStructureBuildGeometryInfoKHR& info,
                       VkAccelerationStructureGeometryKHR& g, const VkAccelerationStructureBuildRangeInfoKHR& range);
  const void* Chain(ByteSource& in);
  VkDeviceOrHostAddressConstKHR Address(ByteSource& in);

  SyntheticDevice& device_;
  bool host_;
  bool short_arrays_ = false;
  BuildCommand command_;
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos_;
  std::vector<InfoArrays> arrays_;
  std::vector<const VkAccelerationStructureBuildRangeInfoKHR*> range_pointers_;
  std::vector<const uint32_t*> max_count_pointers_;
  std::vector<VkDeviceAddress> indirect_addresses_;
  std::vector<uint32_t> indirect_strides_;
  std::vector<std::unique_ptr<ChainNode>> chain_nodes_;
  // Host instance geometries' arrays of pointers, each in storage of its own, of exactly the length the range
  // reads (in the arena, another geometry's pointers could overwrite some of its bytes).
  std::vector<std::vector<uint8_t>> pointer_arrays_;
};

}  // namespace asval::fuzz
