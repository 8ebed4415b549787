#include "host_instances.h"

#include <algorithm>
#include <cstddef>
#include <cstring>

namespace asval {

namespace {

// Where instance k's reference lives, or null when its pointer (arrays of pointers) is null.
const unsigned char* InstanceAt(const VkAccelerationStructureGeometryInstancesDataKHR& data,
                                const VkAccelerationStructureBuildRangeInfoKHR& range, uint32_t k) {
  const auto* base = static_cast<const unsigned char*>(data.data.hostAddress) + range.primitiveOffset;
  if (data.arrayOfPointers == VK_TRUE) {
    const void* pointer = nullptr;
    std::memcpy(&pointer, base + k * sizeof(void*), sizeof(pointer));  // the app may misalign (pInfos-03716)
    return static_cast<const unsigned char*>(pointer);
  }
  return base + k * sizeof(VkAccelerationStructureInstanceKHR);
}

uint64_t ReferenceOf(const unsigned char* instance) {
  uint64_t reference = 0;
  std::memcpy(&reference, instance + offsetof(VkAccelerationStructureInstanceKHR, accelerationStructureReference),
              sizeof(reference));
  return reference;
}

// The instance data of geometry j of pInfos[i] if it can be read here.
const VkAccelerationStructureGeometryInstancesDataKHR* ReadableInstances(const BuildCommand& cmd, uint32_t i,
                                                                         uint32_t j) {
  if (!cmd.is_host() || !cmd.ranges || !cmd.ranges[i]) return nullptr;
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
  if (info.flags & VK_BUILD_ACCELERATION_STRUCTURE_MOTION_BIT_NV) return nullptr;
  const VkAccelerationStructureGeometryKHR* g = GeometryAt(info, j);
  if (!g || g->geometryType != VK_GEOMETRY_TYPE_INSTANCES_KHR || !g->geometry.instances.data.hostAddress) {
    return nullptr;
  }
  return &g->geometry.instances;
}

}  // namespace

bool CollectInstanceReferences(const BuildCommand& cmd, uint32_t i, uint32_t j, std::vector<uint64_t>& out) {
  const VkAccelerationStructureGeometryInstancesDataKHR* data = ReadableInstances(cmd, i, j);
  if (!data) return false;
  const VkAccelerationStructureBuildRangeInfoKHR& range = cmd.ranges[i][j];
  for (uint32_t k = 0; k < range.primitiveCount; ++k) {
    const unsigned char* instance = InstanceAt(*data, range, k);
    if (!instance) continue;
    const uint64_t reference = ReferenceOf(instance);
    if (reference != 0) out.push_back(reference);  // 0: an inactive instance
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return true;
}

uint32_t FirstInstanceReferencing(const BuildCommand& cmd, uint32_t i, uint32_t j, uint64_t reference) {
  const VkAccelerationStructureGeometryInstancesDataKHR* data = ReadableInstances(cmd, i, j);
  if (!data) return 0;
  const VkAccelerationStructureBuildRangeInfoKHR& range = cmd.ranges[i][j];
  for (uint32_t k = 0; k < range.primitiveCount; ++k) {
    const unsigned char* instance = InstanceAt(*data, range, k);
    if (instance && ReferenceOf(instance) == reference) return k;
  }
  return range.primitiveCount;
}

}  // namespace asval
