#include "host_instances.h"

#include <algorithm>
#include <cstddef>
#include <cstring>

#include "host_reads.h"

namespace asval {

namespace {

constexpr uint64_t kInstanceBytes = sizeof(VkAccelerationStructureInstanceKHR);

// Where instance k's reference lives, or null when its pointer (arrays of pointers) is null or, on a device without
// host commands, points outside the app's mappings (host_reads.h).
const unsigned char* InstanceAt(const DeviceState& state, const VkAccelerationStructureGeometryInstancesDataKHR& data,
                                const VkAccelerationStructureBuildRangeInfoKHR& range, uint32_t k) {
  const auto* base = static_cast<const unsigned char*>(data.data.hostAddress) + range.primitiveOffset;
  if (data.arrayOfPointers == VK_TRUE) {
    const void* pointer = nullptr;
    std::memcpy(&pointer, base + k * sizeof(void*), sizeof(pointer));  // the app may misalign (pInfos-03716)
    if (pointer && !HostBytesReadable(state, pointer, kInstanceBytes)) return nullptr;
    return static_cast<const unsigned char*>(pointer);
  }
  return base + k * kInstanceBytes;
}

uint64_t ReferenceOf(const unsigned char* instance) {
  uint64_t reference = 0;
  std::memcpy(&reference, instance + offsetof(VkAccelerationStructureInstanceKHR, accelerationStructureReference),
              sizeof(reference));
  return reference;
}

// The instance data of geometry j of pInfos[i] if it can be read here: the records, or the array of pointers (whose
// records InstanceAt checks one by one).
const VkAccelerationStructureGeometryInstancesDataKHR* ReadableInstances(const DeviceState& state,
                                                                         const BuildCommand& cmd, uint32_t i,
                                                                         uint32_t j) {
  if (!cmd.is_host() || !cmd.ranges || !cmd.ranges[i]) return nullptr;
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
  if (info.flags & VK_BUILD_ACCELERATION_STRUCTURE_MOTION_BIT_NV) return nullptr;
  const VkAccelerationStructureGeometryKHR* g = GeometryAt(info, j);
  if (!g || g->geometryType != VK_GEOMETRY_TYPE_INSTANCES_KHR || !g->geometry.instances.data.hostAddress) {
    return nullptr;
  }
  const VkAccelerationStructureGeometryInstancesDataKHR& data = g->geometry.instances;
  const VkAccelerationStructureBuildRangeInfoKHR& range = cmd.ranges[i][j];
  const uint64_t element = data.arrayOfPointers == VK_TRUE ? sizeof(void*) : kInstanceBytes;
  if (!HostBytesReadable(state, data.data.hostAddress, range.primitiveOffset + range.primitiveCount * element)) {
    return nullptr;
  }
  return &data;
}

}  // namespace

bool CollectInstanceReferences(const DeviceState& state, const BuildCommand& cmd, uint32_t i, uint32_t j,
                               std::vector<uint64_t>& out) {
  const VkAccelerationStructureGeometryInstancesDataKHR* data = ReadableInstances(state, cmd, i, j);
  if (!data) return false;
  const VkAccelerationStructureBuildRangeInfoKHR& range = cmd.ranges[i][j];
  for (uint32_t k = 0; k < range.primitiveCount; ++k) {
    const unsigned char* instance = InstanceAt(state, *data, range, k);
    if (!instance) continue;
    const uint64_t reference = ReferenceOf(instance);
    if (reference != 0) out.push_back(reference);  // 0: an inactive instance
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return true;
}

uint32_t FirstInstanceReferencing(const DeviceState& state, const BuildCommand& cmd, uint32_t i, uint32_t j,
                                  uint64_t reference) {
  const VkAccelerationStructureGeometryInstancesDataKHR* data = ReadableInstances(state, cmd, i, j);
  if (!data) return 0;
  const VkAccelerationStructureBuildRangeInfoKHR& range = cmd.ranges[i][j];
  for (uint32_t k = 0; k < range.primitiveCount; ++k) {
    const unsigned char* instance = InstanceAt(state, *data, range, k);
    if (instance && ReferenceOf(instance) == reference) return k;
  }
  return range.primitiveCount;
}

}  // namespace asval
