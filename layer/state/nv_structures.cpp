#include "nv_structures.h"

#include <new>

#include "failure_injection.h"
#include "history.h"
#include "vk_dispatch_table.h"

namespace asval {

namespace {

VkDeviceSize RequirementSize(const DeviceDispatchTable& dispatch, VkDevice device, VkAccelerationStructureNV handle,
                             VkAccelerationStructureMemoryRequirementsTypeNV type) {
  if (!dispatch.GetAccelerationStructureMemoryRequirementsNV) return 0;
  const VkAccelerationStructureMemoryRequirementsInfoNV info{
      VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_INFO_NV, nullptr, type, handle};
  VkMemoryRequirements2KHR requirements{VK_STRUCTURE_TYPE_MEMORY_REQUIREMENTS_2, nullptr, {}};
  dispatch.GetAccelerationStructureMemoryRequirementsNV(device, &info, &requirements);
  return requirements.memoryRequirements.size;
}

void Forget(DeviceState& state, VkAccelerationStructureKHR key) {
  std::unique_lock<std::mutex> lock = state.history.store.Lock();
  try {
    state.history.store.Forget(key);
  } catch (const std::bad_alloc&) {
    state.failures().allocation_failures.fetch_add(1, std::memory_order_relaxed);
  }
}

}  // namespace

void RecordCreateAccelerationStructureNV(DeviceState& state, const DeviceDispatchTable& dispatch, VkDevice device,
                                         const VkAccelerationStructureCreateInfoNV& create,
                                         VkAccelerationStructureNV handle) try {
  InjectBadAlloc(FailSite::kStructureRecord);
  auto record = std::make_shared<NvStructureState>();
  record->handle = handle;
  record->serial = state.NextObjectId();
  const VkAccelerationStructureInfoNV& info = create.info;
  record->type = info.type;
  record->flags = info.flags;
  record->instance_count = info.instanceCount;
  record->compacted_size = create.compactedSize;
  if (info.pGeometries) {
    record->geometries.reserve(info.geometryCount);
    for (uint32_t j = 0; j < info.geometryCount; ++j) {
      const VkGeometryNV& g = info.pGeometries[j];
      NvStructureState::GeometryRoom room;
      room.type = g.geometryType;
      room.vertices = g.geometry.triangles.vertexCount;
      room.indices = g.geometry.triangles.indexType == VK_INDEX_TYPE_NONE_NV ? 0 : g.geometry.triangles.indexCount;
      room.aabbs = g.geometry.aabbs.numAABBs;
      record->geometries.push_back(room);
    }
  }
  record->object_size =
      RequirementSize(dispatch, device, handle, VK_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_TYPE_OBJECT_NV);
  record->build_scratch_size =
      RequirementSize(dispatch, device, handle, VK_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_TYPE_BUILD_SCRATCH_NV);
  record->update_scratch_size =
      RequirementSize(dispatch, device, handle, VK_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_TYPE_UPDATE_SCRATCH_NV);
  // Handles of different types may share a value: such a structure is kept out of the history (its rules skip).
  record->shares_key = state.acceleration_structures.contains(NvHistoryKey(handle));
  const bool shares_key = record->shares_key;
  state.nv_structures.insert_or_assign(handle, std::move(record));
  if (!shares_key) Forget(state, NvHistoryKey(handle));  // a record left under the value by a destroyed structure
} catch (const std::bad_alloc&) {
  // Unknown to the layer: its rules skip and count, and the history never records it (history_apply.cpp: Fresh).
  state.failures().structures_incomplete.store(true, std::memory_order_relaxed);
  state.nv_structures.erase(handle);
}

void RecordBindAccelerationStructureMemoryNV(DeviceState& state, const VkBindAccelerationStructureMemoryInfoNV& bind) {
  std::optional<std::shared_ptr<const NvStructureState>> found = state.nv_structures.find(bind.accelerationStructure);
  if (!found || !*found) return;
  try {
    auto record = std::make_shared<NvStructureState>(**found);
    record->bound = true;
    record->memory = bind.memory;
    record->memory_offset = bind.memoryOffset;
    state.nv_structures.insert_or_assign(bind.accelerationStructure, std::move(record));
  } catch (const std::bad_alloc&) {
    state.failures().structures_incomplete.store(true, std::memory_order_relaxed);
    state.nv_structures.erase(bind.accelerationStructure);
  }
}

void RecordDestroyAccelerationStructureNV(DeviceState& state, VkAccelerationStructureNV handle) {
  std::optional<std::shared_ptr<const NvStructureState>> record = state.nv_structures.pop(handle);
  if (record && *record && !(*record)->shares_key) Forget(state, NvHistoryKey(handle));
}

void NoteKhrStructureKey(DeviceState& state, VkAccelerationStructureKHR handle) {
  const VkAccelerationStructureNV nv = NvHandleOf(handle);
  std::optional<std::shared_ptr<const NvStructureState>> found = state.nv_structures.find(nv);
  if (!found || !*found || (*found)->shares_key) return;
  Forget(state, handle);  // the NV structure's history is not the new structure's
  try {
    auto record = std::make_shared<NvStructureState>(**found);
    record->shares_key = true;
    state.nv_structures.insert_or_assign(nv, std::move(record));
  } catch (const std::bad_alloc&) {
    state.failures().structures_incomplete.store(true, std::memory_order_relaxed);
    state.nv_structures.erase(nv);
  }
}

std::shared_ptr<const NvStructureState> FindNvByKey(const DeviceState& state, VkAccelerationStructureKHR key) {
  if (key == VK_NULL_HANDLE || !state.features.nv_ray_tracing) return nullptr;  // no NV structure can exist
  std::optional<std::shared_ptr<const NvStructureState>> found = state.nv_structures.find(NvHandleOf(key));
  if (!found || !*found || (*found)->shares_key) return nullptr;
  return std::move(*found);
}

std::optional<MemorySpan> NvStructureSpan(const NvStructureState& structure) {
  if (!structure.bound || structure.object_size == 0) return std::nullopt;
  if (structure.memory_offset > ~VkDeviceSize{0} - structure.object_size) return std::nullopt;
  return MemorySpan{structure.memory, structure.memory_offset, structure.memory_offset + structure.object_size};
}

}  // namespace asval
