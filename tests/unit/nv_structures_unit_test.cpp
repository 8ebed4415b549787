// VK_NV_ray_tracing structures in the shadow state without a driver (layer/state/nv_structures.h): what creation and
// binding keep, the bytes a structure occupies, and the structures kept out of the history because a live KHR
// structure has their handle value (handles of different types may share values).
#include <catch2/catch_test_macros.hpp>

#include "nv_structures.h"
#include "state_tracker.h"
#include "vk_dispatch_table.h"

namespace asval {
namespace {

template <typename H>
H Fake(uintptr_t v) {
  return reinterpret_cast<H>(v);
}

// The fake driver's memory requirements: object 4096 bytes, build scratch 512, update scratch 256.
VKAPI_ATTR void VKAPI_CALL FakeRequirements(VkDevice, const VkAccelerationStructureMemoryRequirementsInfoNV* info,
                                            VkMemoryRequirements2KHR* out) {
  switch (info->type) {
    case VK_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_TYPE_OBJECT_NV:
      out->memoryRequirements.size = 4096;
      break;
    case VK_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_TYPE_BUILD_SCRATCH_NV:
      out->memoryRequirements.size = 512;
      break;
    default:
      out->memoryRequirements.size = 256;
      break;
  }
}

VkAccelerationStructureCreateInfoNV TwoGeometries(VkGeometryNV* geometries) {
  geometries[0] = VkGeometryNV{VK_STRUCTURE_TYPE_GEOMETRY_NV};
  geometries[0].geometryType = VK_GEOMETRY_TYPE_TRIANGLES_NV;
  geometries[0].geometry.triangles.vertexCount = 9;
  geometries[0].geometry.triangles.indexType = VK_INDEX_TYPE_UINT32;
  geometries[0].geometry.triangles.indexCount = 6;
  geometries[1] = VkGeometryNV{VK_STRUCTURE_TYPE_GEOMETRY_NV};
  geometries[1].geometryType = VK_GEOMETRY_TYPE_AABBS_NV;
  geometries[1].geometry.aabbs.numAABBs = 5;
  VkAccelerationStructureCreateInfoNV create{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_NV};
  create.info.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_INFO_NV;
  create.info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_NV;
  create.info.flags = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_NV;
  create.info.geometryCount = 2;
  create.info.pGeometries = geometries;
  return create;
}

TEST_CASE(
    "nv state unit: creation keeps each geometry's room and the driver's three sizes; binding places the "
    "structure's bytes",
    "[unit][nv]") {
  DeviceState state;
  state.features.nv_ray_tracing = true;
  DeviceDispatchTable dispatch{};
  dispatch.GetAccelerationStructureMemoryRequirementsNV = &FakeRequirements;
  VkGeometryNV geometries[2];
  const VkAccelerationStructureNV nv = Fake<VkAccelerationStructureNV>(0x1100);
  RecordCreateAccelerationStructureNV(state, dispatch, Fake<VkDevice>(1), TwoGeometries(geometries), nv);
  std::shared_ptr<const NvStructureState> s = FindNvByKey(state, NvHistoryKey(nv));
  REQUIRE(s);
  CHECK(s->flags == VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_NV);
  REQUIRE(s->geometries.size() == 2);
  CHECK(s->geometries[0].vertices == 9);
  CHECK(s->geometries[0].indices == 6);
  CHECK(s->geometries[1].aabbs == 5);
  CHECK(s->object_size == 4096);
  CHECK(s->build_scratch_size == 512);
  CHECK(s->update_scratch_size == 256);
  CHECK_FALSE(NvStructureSpan(*s));  // not bound yet

  VkBindAccelerationStructureMemoryInfoNV bind{VK_STRUCTURE_TYPE_BIND_ACCELERATION_STRUCTURE_MEMORY_INFO_NV};
  bind.accelerationStructure = nv;
  bind.memory = Fake<VkDeviceMemory>(50);
  bind.memoryOffset = 8192;
  RecordBindAccelerationStructureMemoryNV(state, bind);
  s = FindNvByKey(state, NvHistoryKey(nv));
  REQUIRE(s);
  const std::optional<MemorySpan> span = NvStructureSpan(*s);
  REQUIRE(span);
  CHECK(span->memory == Fake<VkDeviceMemory>(50));
  CHECK(span->begin == 8192);
  CHECK(span->end == 8192 + 4096);

  RecordDestroyAccelerationStructureNV(state, nv);
  CHECK_FALSE(FindNvByKey(state, NvHistoryKey(nv)));
}

TEST_CASE(
    "nv state unit: an NV structure whose handle value a live KHR structure has, created before or after it, "
    "is kept out of the history; without the extension no key names an NV structure",
    "[unit][nv]") {
  DeviceState state;
  state.features.nv_ray_tracing = true;
  DeviceDispatchTable dispatch{};
  dispatch.GetAccelerationStructureMemoryRequirementsNV = &FakeRequirements;
  VkGeometryNV geometries[2];
  VkAccelerationStructureCreateInfoKHR khr{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
  khr.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  khr.size = 4096;

  // KHR first, then NV under the same value.
  RecordCreateAccelerationStructure(state, dispatch, Fake<VkDevice>(1), khr, Fake<VkAccelerationStructureKHR>(0x700));
  const VkAccelerationStructureNV late = Fake<VkAccelerationStructureNV>(0x700);
  RecordCreateAccelerationStructureNV(state, dispatch, Fake<VkDevice>(1), TwoGeometries(geometries), late);
  REQUIRE(state.nv_structures.find(late));
  CHECK((*state.nv_structures.find(late))->shares_key);
  CHECK_FALSE(FindNvByKey(state, NvHistoryKey(late)));

  // NV first, then KHR under the same value.
  const VkAccelerationStructureNV early = Fake<VkAccelerationStructureNV>(0x900);
  RecordCreateAccelerationStructureNV(state, dispatch, Fake<VkDevice>(1), TwoGeometries(geometries), early);
  CHECK(FindNvByKey(state, NvHistoryKey(early)));
  RecordCreateAccelerationStructure(state, dispatch, Fake<VkDevice>(1), khr, Fake<VkAccelerationStructureKHR>(0x900));
  REQUIRE(state.nv_structures.find(early));
  CHECK((*state.nv_structures.find(early))->shares_key);
  CHECK_FALSE(FindNvByKey(state, NvHistoryKey(early)));

  // A device without the extension: no lookup, whatever the maps hold.
  const VkAccelerationStructureNV alone = Fake<VkAccelerationStructureNV>(0xb00);
  RecordCreateAccelerationStructureNV(state, dispatch, Fake<VkDevice>(1), TwoGeometries(geometries), alone);
  CHECK(FindNvByKey(state, NvHistoryKey(alone)));
  state.features.nv_ray_tracing = false;
  CHECK_FALSE(FindNvByKey(state, NvHistoryKey(alone)));
}

}  // namespace
}  // namespace asval
