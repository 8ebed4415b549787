#include "bottom_levels.h"

#include <algorithm>

#include "device_buffers.h"

namespace refit {

namespace {

constexpr VkDeviceSize kVertexStride = 3 * sizeof(float);
constexpr VkDeviceSize kStructureAlignment = 256;  // VkAccelerationStructureCreateInfoKHR::offset

VkDeviceSize AlignUp(VkDeviceSize value, VkDeviceSize alignment) {
  return (value + alignment - 1) / alignment * alignment;
}

}  // namespace

BottomLevels::BottomLevels(vkkit::Device& device, const vkkit::Buffer& positions, const vkkit::Buffer& indices,
                           uint32_t vertices_per_mesh, uint32_t triangles, uint32_t structures)
    : device_(device),
      geometries_(structures),
      infos_(structures),
      ranges_(structures),
      range_pointers_(structures) {
  for (uint32_t i = 0; i < structures; ++i) {
    VkAccelerationStructureGeometryKHR& g = geometries_[i];
    g.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR;
    g.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
    g.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
    VkAccelerationStructureGeometryTrianglesDataKHR& t = g.geometry.triangles;
    t.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
    t.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    t.vertexData.deviceAddress = positions.address + VkDeviceSize{i} * vertices_per_mesh * kVertexStride;
    t.vertexStride = kVertexStride;
    t.maxVertex = vertices_per_mesh - 1;
    t.indexType = VK_INDEX_TYPE_UINT32;
    t.indexData.deviceAddress = indices.address;
    ranges_[i].primitiveCount = triangles;
    range_pointers_[i] = &ranges_[i];
    VkAccelerationStructureBuildGeometryInfoKHR& info = infos_[i];
    info.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR;
    info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    info.flags = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR |
                 VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
    info.geometryCount = 1;
    info.pGeometries = &g;
  }
  // Every structure has the same geometry description (one mesh), so one size query serves all.
  VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
  device.GetAccelerationStructureBuildSizesKHR(device.handle(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR,
                                               &infos_[0], &triangles, &sizes);
  const VkDeviceSize span = AlignUp(sizes.accelerationStructureSize, kStructureAlignment);
  const VkDeviceSize slice_alignment =
      std::max<VkDeviceSize>(1, device.as_properties().minAccelerationStructureScratchOffsetAlignment);
  const VkDeviceSize slice = AlignUp(std::max(sizes.buildScratchSize, sizes.updateScratchSize), slice_alignment);
  storage_ = CreateDeviceLocalBuffer(device, span * structures, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR);
  scratch_ = CreateDeviceLocalBuffer(device, slice * structures, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  for (uint32_t i = 0; i < structures; ++i) {
    VkAccelerationStructureCreateInfoKHR create{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
    create.buffer = storage_.buffer;
    create.offset = span * i;
    create.size = sizes.accelerationStructureSize;
    create.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    VkAccelerationStructureKHR handle = VK_NULL_HANDLE;
    vkkit::Check(device.CreateAccelerationStructureKHR(device.handle(), &create, nullptr, &handle),
                 "vkCreateAccelerationStructureKHR");
    structures_.push_back(handle);
    VkAccelerationStructureDeviceAddressInfoKHR address{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR};
    address.accelerationStructure = handle;
    addresses_.push_back(device.GetAccelerationStructureDeviceAddressKHR(device.handle(), &address));
    infos_[i].dstAccelerationStructure = handle;
    infos_[i].scratchData.deviceAddress = scratch_.address + slice * i;
  }
}

BottomLevels::~BottomLevels() {
  for (VkAccelerationStructureKHR s : structures_) device_.DestroyAccelerationStructureKHR(device_.handle(), s, nullptr);
  device_.Destroy(scratch_);
  device_.Destroy(storage_);
}

void BottomLevels::Record(VkCommandBuffer cb, VkBuildAccelerationStructureModeKHR mode, Shape shape) {
  const bool update = mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
  for (VkAccelerationStructureBuildGeometryInfoKHR& info : infos_) {
    info.mode = mode;
    info.srcAccelerationStructure = update ? info.dstAccelerationStructure : VK_NULL_HANDLE;
  }
  const uint32_t count = static_cast<uint32_t>(infos_.size());
  if (shape == Shape::kOneCall) {
    device_.CmdBuildAccelerationStructuresKHR(cb, count, infos_.data(), range_pointers_.data());
  } else {
    for (uint32_t i = 0; i < count; ++i) device_.CmdBuildAccelerationStructuresKHR(cb, 1, &infos_[i], &range_pointers_[i]);
  }
  // The top level reads what these wrote.
  VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  barrier.srcAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;
  barrier.dstAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR;
  const VkPipelineStageFlags stage = VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR;
  vkCmdPipelineBarrier(cb, stage, stage, 0, 1, &barrier, 0, nullptr, 0, nullptr);
}

}  // namespace refit
