// vkBuildAccelerationStructuresKHR on the device below: every host input a geometry reads (host_inputs.h) is
// copied into one staging buffer, instance references (handles, for host builds) become device addresses, and the
// same build is recorded with device addresses and a scratch area of the staging buffer's.
#include <cstring>
#include <vector>

#include "device_executor.h"
#include "driver_dispatch.h"
#include "host_commands.h"
#include "host_inputs.h"

namespace asval_test_driver {
namespace {

constexpr VkDeviceSize kAlign = 256;  // every copy and the scratch: above any alignment a build asks for

VkDeviceSize AlignUp(VkDeviceSize v) { return (v + kAlign - 1) / kAlign * kAlign; }

const VkAccelerationStructureGeometryKHR& GeometryOf(const VkAccelerationStructureBuildGeometryInfoKHR& info,
                                                     uint32_t g) {
  return info.pGeometries != nullptr ? info.pGeometries[g] : *info.ppGeometries[g];
}

// One host span to copy: from `source` + span.offset to staging + at.
struct Copy {
  const unsigned char* source = nullptr;
  HostSpan span;
  VkDeviceSize at = 0;
};

// The build as the device will run it, and where each of its inputs goes in the staging buffer.
struct DeviceBuild {
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos;
  std::vector<std::vector<VkAccelerationStructureGeometryKHR>> geometries;
  std::vector<std::vector<VkAccelerationStructureBuildRangeInfoKHR>> ranges;
  std::vector<Copy> copies;
  std::vector<std::vector<VkAccelerationStructureInstanceKHR>> instances;  // packed, references as addresses
  std::vector<VkDeviceSize> instance_at;
  std::vector<VkDeviceSize> scratch_at;
  VkDeviceSize bytes = 0;
};

VkDeviceSize Place(DeviceBuild& build, VkDeviceSize bytes) {
  const VkDeviceSize at = build.bytes;
  build.bytes = AlignUp(build.bytes + bytes);
  return at;
}

// The staging offset minus the span's own offset: the device adds the range's offsets to it, as the host
// build would have added them to the host address.
VkDeviceAddress Rebased(VkDeviceAddress staging, const Copy& copy) { return staging + copy.at - copy.span.offset; }

VkDeviceAddress ReferenceAddress(DeviceData& device, uint64_t handle) {
  if (handle == 0) return 0;
  VkAccelerationStructureDeviceAddressInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR};
  info.accelerationStructure = reinterpret_cast<VkAccelerationStructureKHR>(handle);
  return device.vk.GetAccelerationStructureDeviceAddressKHR(device.device, &info);
}

std::vector<VkAccelerationStructureInstanceKHR> PackInstances(DeviceData& device,
                                                              const VkAccelerationStructureGeometryInstancesDataKHR& g,
                                                              const VkAccelerationStructureBuildRangeInfoKHR& range) {
  std::vector<VkAccelerationStructureInstanceKHR> packed(range.primitiveCount);
  const auto* base = static_cast<const unsigned char*>(g.data.hostAddress) + range.primitiveOffset;
  for (uint32_t i = 0; i < range.primitiveCount; ++i) {
    const void* source = base + i * sizeof(VkAccelerationStructureInstanceKHR);
    if (g.arrayOfPointers) std::memcpy(&source, base + i * sizeof(void*), sizeof(void*));
    std::memcpy(&packed[i], source, sizeof(packed[i]));
    packed[i].accelerationStructureReference = ReferenceAddress(device, packed[i].accelerationStructureReference);
  }
  return packed;
}

void PlanGeometry(DeviceData& device, DeviceBuild& build, VkAccelerationStructureGeometryKHR& g,
                  VkAccelerationStructureBuildRangeInfoKHR& range) {
  auto add = [&](const void* source, HostSpan span) {
    build.copies.push_back(Copy{static_cast<const unsigned char*>(source), span, Place(build, span.bytes)});
  };
  if (g.geometryType == VK_GEOMETRY_TYPE_TRIANGLES_KHR) {
    const auto& t = g.geometry.triangles;
    const HostSpan indices = IndexSpan(t, range);
    uint64_t largest = 3ull * range.primitiveCount - 1;
    if (indices.bytes != 0) {
      largest = LargestIndex(static_cast<const unsigned char*>(t.indexData.hostAddress) + indices.offset, t.indexType,
                             3ull * range.primitiveCount);
      add(t.indexData.hostAddress, indices);
    }
    if (range.primitiveCount != 0) add(t.vertexData.hostAddress, VertexSpan(t, range, largest));
    if (t.transformData.hostAddress != nullptr) add(t.transformData.hostAddress, TransformSpan(t, range));
  } else if (g.geometryType == VK_GEOMETRY_TYPE_AABBS_KHR) {
    if (range.primitiveCount != 0) add(g.geometry.aabbs.data.hostAddress, AabbSpan(g.geometry.aabbs, range));
  } else if (g.geometryType == VK_GEOMETRY_TYPE_INSTANCES_KHR) {
    build.instances.push_back(PackInstances(device, g.geometry.instances, range));
    build.instance_at.push_back(
        Place(build, build.instances.back().size() * sizeof(VkAccelerationStructureInstanceKHR)));
  }
}

// Points the geometry's addresses into the staging buffer, taking its copies in the order PlanGeometry made them.
void Rebase(DeviceBuild& build, VkDeviceAddress staging, VkAccelerationStructureGeometryKHR& g,
            VkAccelerationStructureBuildRangeInfoKHR& range, size_t* next_copy, size_t* next_instances) {
  if (g.geometryType == VK_GEOMETRY_TYPE_TRIANGLES_KHR) {
    auto& t = g.geometry.triangles;
    if (IndexSpan(t, range).bytes != 0) t.indexData.deviceAddress = Rebased(staging, build.copies[(*next_copy)++]);
    if (range.primitiveCount != 0) t.vertexData.deviceAddress = Rebased(staging, build.copies[(*next_copy)++]);
    if (t.transformData.hostAddress != nullptr) {
      t.transformData.deviceAddress = Rebased(staging, build.copies[(*next_copy)++]);
    }
    FoldFirstVertex(g, range);
  } else if (g.geometryType == VK_GEOMETRY_TYPE_AABBS_KHR) {
    if (range.primitiveCount != 0) g.geometry.aabbs.data.deviceAddress = Rebased(staging, build.copies[(*next_copy)++]);
  } else if (g.geometryType == VK_GEOMETRY_TYPE_INSTANCES_KHR) {
    g.geometry.instances.arrayOfPointers = VK_FALSE;
    g.geometry.instances.data.deviceAddress = staging + build.instance_at[(*next_instances)++];
    range.primitiveOffset = 0;
  }
}

}  // namespace

VkResult BuildOnHost(DeviceData& device, uint32_t info_count, const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                     const VkAccelerationStructureBuildRangeInfoKHR* const* ranges) {
  DeviceBuild build;
  build.infos.assign(infos, infos + info_count);
  build.geometries.resize(info_count);
  build.ranges.resize(info_count);
  for (uint32_t i = 0; i < info_count; ++i) {
    const auto& info = infos[i];
    for (uint32_t g = 0; g < info.geometryCount; ++g) {
      build.geometries[i].push_back(GeometryOf(info, g));
      build.ranges[i].push_back(ranges[i][g]);
      PlanGeometry(device, build, build.geometries[i].back(), build.ranges[i].back());
    }
    std::vector<uint32_t> counts;
    for (const auto& r : build.ranges[i]) counts.push_back(r.primitiveCount);
    VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
    VkAccelerationStructureBuildGeometryInfoKHR query = info;
    query.pGeometries = build.geometries[i].data();
    query.ppGeometries = nullptr;
    device.vk.GetAccelerationStructureBuildSizesKHR(device.device, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR,
                                                    &query, counts.data(), &sizes);
    build.scratch_at.push_back(Place(build, info.mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR
                                                ? sizes.updateScratchSize
                                                : sizes.buildScratchSize));
  }

  StagingBuffer staging;
  VkResult result = device.executor->CreateStaging(build.bytes, &staging);
  if (result != VK_SUCCESS) return result;
  for (const Copy& copy : build.copies)
    std::memcpy(staging.mapped + copy.at, copy.source + copy.span.offset, copy.span.bytes);
  for (size_t k = 0; k < build.instances.size(); ++k) {
    std::memcpy(staging.mapped + build.instance_at[k], build.instances[k].data(),
                build.instances[k].size() * sizeof(VkAccelerationStructureInstanceKHR));
  }
  size_t next_copy = 0, next_instances = 0;
  std::vector<const VkAccelerationStructureBuildRangeInfoKHR*> range_pointers;
  for (uint32_t i = 0; i < info_count; ++i) {
    for (uint32_t g = 0; g < infos[i].geometryCount; ++g) {
      Rebase(build, staging.address, build.geometries[i][g], build.ranges[i][g], &next_copy, &next_instances);
    }
    build.infos[i].pGeometries = build.geometries[i].data();
    build.infos[i].ppGeometries = nullptr;
    build.infos[i].scratchData.deviceAddress = staging.address + build.scratch_at[i];
    range_pointers.push_back(build.ranges[i].data());
  }
  result = device.executor->Run([&](VkCommandBuffer cb) {
    device.vk.CmdBuildAccelerationStructuresKHR(cb, info_count, build.infos.data(), range_pointers.data());
  });
  device.executor->DestroyStaging(&staging);
  return result;
}

}  // namespace asval_test_driver
