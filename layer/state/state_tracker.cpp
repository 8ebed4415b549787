#include "state_tracker.h"

#include <new>

#include "failure_injection.h"
#include "nv_structures.h"
#include "vk_dispatch_table.h"
#include "vk_struct_chain.h"

namespace asval {

namespace {

// A shadow record could not be made (the layer's allocation failed): the handle is left unknown to the layer, as
// for an object created before it saw the device, so that the checks that need it skip and count; never a record
// that says something else than what the driver did.
void Untracked(const DeviceState& state) {
  state.failures().allocation_failures.fetch_add(1, std::memory_order_relaxed);
  state.failures().objects_untracked.fetch_add(1, std::memory_order_relaxed);
}

// The allocation failed while forgetting an object (a destruction, a free): what was forgotten stays forgotten;
// the rest is said in the summary.
void ForgetFailed(const DeviceState& state) {
  state.failures().allocation_failures.fetch_add(1, std::memory_order_relaxed);
}

}  // namespace

namespace {

// Whether a buffer of the layer's may be bound to memory allocated with `info` (MemoryState::layer_may_bind), and
// the buffer a dedicated allocation is for. Any structure in the chain that is not listed here (an import, an
// export with handle types, a vendor's) makes the memory one the layer leaves alone.
bool LayerMayBind(const VkMemoryAllocateInfo& info, VkMemoryPropertyFlags property_flags, VkBuffer* dedicated_buffer) {
  bool may = (property_flags & VK_MEMORY_PROPERTY_PROTECTED_BIT) == 0;
  for (auto* s = static_cast<const VkBaseInStructure*>(info.pNext); s; s = s->pNext) {
    switch (s->sType) {
      case VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO:
      case VK_STRUCTURE_TYPE_MEMORY_PRIORITY_ALLOCATE_INFO_EXT:
      case VK_STRUCTURE_TYPE_MEMORY_OPAQUE_CAPTURE_ADDRESS_ALLOCATE_INFO:
        break;
      case VK_STRUCTURE_TYPE_MEMORY_DEDICATED_ALLOCATE_INFO: {
        auto* dedicated = reinterpret_cast<const VkMemoryDedicatedAllocateInfo*>(s);
        if (dedicated->buffer != VK_NULL_HANDLE || dedicated->image != VK_NULL_HANDLE) may = false;
        *dedicated_buffer = dedicated->buffer;
        break;
      }
      case VK_STRUCTURE_TYPE_EXPORT_MEMORY_ALLOCATE_INFO:
        if (reinterpret_cast<const VkExportMemoryAllocateInfo*>(s)->handleTypes != 0) may = false;
        break;
      default:
        may = false;
        break;
    }
  }
  return may;
}

void AllocateMemoryRecord(DeviceState& state, const VkMemoryAllocateInfo& info, VkDeviceMemory memory) {
  InjectBadAlloc(FailSite::kObjectRecord);
  auto record = std::make_shared<MemoryState>();
  record->handle = memory;
  record->size = info.allocationSize;
  record->type_index = info.memoryTypeIndex;
  if (info.memoryTypeIndex < state.properties.memory.memoryTypeCount) {
    record->property_flags = state.properties.memory.memoryTypes[info.memoryTypeIndex].propertyFlags;
  }
  record->layer_may_bind = info.memoryTypeIndex < state.properties.memory.memoryTypeCount &&
                           LayerMayBind(info, record->property_flags, &record->dedicated_buffer);
  auto* flags = FindInChain<VkMemoryAllocateFlagsInfo>(info.pNext, VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO);
  if (flags) record->allocate_flags = flags->flags;
  if (flags && (flags->flags & VK_MEMORY_ALLOCATE_DEVICE_MASK_BIT)) {
    record->multi_instance = __builtin_popcount(flags->deviceMask) > 1;
  } else if (info.memoryTypeIndex < state.properties.memory.memoryTypeCount) {
    const uint32_t heap = state.properties.memory.memoryTypes[info.memoryTypeIndex].heapIndex;
    record->multi_instance = state.features.physical_device_count > 1 &&
                             heap < state.properties.memory.memoryHeapCount &&
                             (state.properties.memory.memoryHeaps[heap].flags & VK_MEMORY_HEAP_MULTI_INSTANCE_BIT);
  }
  state.memories.insert_or_assign(memory, std::move(record));
}

void ForgetBuffersOfMemory(DeviceState& state, VkDeviceMemory memory) {
  // Buffers bound to it keep their binding (it never goes away) but no longer have bytes or a usable device
  // address: their ranges leave the address map, so that a buffer later given the same addresses in another
  // allocation is the only one a lookup finds, and their records forget the memory's handle value.
  const auto bound = state.buffers.snapshot(
      [memory](VkBuffer, const std::shared_ptr<const BufferState>& b) { return b && b->bound && b->memory == memory; });
  bool storage = false;
  for (const auto& [handle, old] : bound) {
    if (old->device_address != 0) state.buffer_addresses.Erase(old->device_address, handle);
    auto record = std::make_shared<BufferState>(*old);
    record->memory = VK_NULL_HANDLE;
    record->memory_freed = true;
    record->device_address = 0;
    storage |= (record->usage & VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR) != 0;
    state.buffers.insert_or_assign(handle, std::move(record));
  }
  if (storage) state.structure_storage_changes.Bump();
}

}  // namespace

void RecordAllocateMemory(DeviceState& state, const VkMemoryAllocateInfo& info, VkDeviceMemory memory) {
  try {
    AllocateMemoryRecord(state, info, memory);
  } catch (const std::bad_alloc&) {
    state.memories.erase(memory);
    Untracked(state);
  }
}

void RecordFreeMemory(DeviceState& state, VkDeviceMemory memory) {
  state.memories.erase(memory);
  state.host_mappings.Unmap(memory);  // freeing unmaps
  try {
    ForgetBuffersOfMemory(state, memory);
  } catch (const std::bad_alloc&) {
    // Buffers bound to it could not all be rewritten: those left are forgotten (unknown) rather than kept bound to
    // a handle value that a later allocation may reuse. Erasing allocates nothing.
    ForgetFailed(state);
    for (;;) {
      VkBuffer stale = VK_NULL_HANDLE;
      try {
        const auto left = state.buffers.snapshot([memory](VkBuffer, const std::shared_ptr<const BufferState>& b) {
          return b && b->bound && b->memory == memory;
        });
        if (!left.empty()) stale = left.front().first;
      } catch (const std::bad_alloc&) {
        break;
      }
      if (stale == VK_NULL_HANDLE) break;
      state.failures().buffers_incomplete.store(true, std::memory_order_relaxed);
      RecordDestroyBuffer(state, stale);
    }
  }
  std::unique_lock<std::mutex> lock = state.history.store.Lock();
  state.history.store.ForgetMemory(memory);  // erases only
}

namespace {

// Asks the driver for a structure's address, as the app may once the buffer it was created on is bound with
// SHADER_DEVICE_ADDRESS usage (the layer's own call then breaks no rule).
AccelerationStructureState::Address AskAddress(const DeviceDispatchTable& dispatch, VkDevice device,
                                               AccelerationStructureState& record) {
  using Address = AccelerationStructureState::Address;
  if (!dispatch.GetAccelerationStructureDeviceAddressKHR) return Address::kUnknown;
  const VkAccelerationStructureDeviceAddressInfoKHR info{
      VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR, nullptr, record.handle};
  record.device_address = dispatch.GetAccelerationStructureDeviceAddressKHR(device, &info);
  return record.device_address != 0 ? Address::kKnown : Address::kUnknown;
}

// What can be known of the address of a structure created on `buffer` (null: a buffer the layer does not know).
AccelerationStructureState::Address AddressAtCreation(const DeviceDispatchTable& dispatch, VkDevice device,
                                                      const BufferState* buffer, AccelerationStructureState& record) {
  using Address = AccelerationStructureState::Address;
  if (!buffer) return Address::kUnknown;
  if (!(buffer->usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT)) return Address::kNone;
  // Bound by vkQueueBindSparse, which the layer does not follow: whether the app could ask is not known.
  if (buffer->create_flags & VK_BUFFER_CREATE_SPARSE_BINDING_BIT) return Address::kUnknown;
  if (!buffer->bound) return Address::kAwaitingBind;
  return AskAddress(dispatch, device, record);
}

// The structures created on `buffer` (its record `bound`, just bound) before it had memory get their addresses.
void AddressStructuresOf(DeviceState& state, const DeviceDispatchTable& dispatch, VkDevice device,
                         const BufferState& bound) try {
  using Address = AccelerationStructureState::Address;
  const auto waiting = state.acceleration_structures.snapshot(
      [&](VkAccelerationStructureKHR, const std::shared_ptr<const AccelerationStructureState>& s) {
        return s && s->address == Address::kAwaitingBind && s->buffer == bound.handle && s->buffer_id == bound.id;
      });
  for (const auto& [handle, old] : waiting) {
    auto record = std::make_shared<AccelerationStructureState>(*old);
    record->address = AskAddress(dispatch, device, *record);
    // Published only over the record it replaces: a thread that destroyed the structure meanwhile wins.
    if (state.acceleration_structures.replace_if(handle, old, std::move(record))) {
      state.structures_awaiting_address.fetch_sub(1, std::memory_order_relaxed);
    }
  }
} catch (const std::bad_alloc&) {
  // A structure left awaiting may have an address now: the snapshots of live structures are never complete again.
  state.failures().structures_incomplete.store(true, std::memory_order_relaxed);
  ForgetFailed(state);
}

}  // namespace

void RecordCreateBuffer(DeviceState& state, const VkBufferCreateInfo& info, VkBuffer buffer, bool copyable) try {
  InjectBadAlloc(FailSite::kObjectRecord);
  auto record = std::make_shared<BufferState>();
  record->handle = buffer;
  record->id = state.NextObjectId();
  record->size = info.size;
  record->usage = info.usage;
  if (auto* usage2 = FindInChain<BufferUsageFlags2CreateInfo>(info.pNext, kBufferUsageFlags2CreateInfo)) {
    // Bits above 31 belong to newer extensions; the rules the layer checks use only the low ones.
    record->usage = static_cast<VkBufferUsageFlags>(usage2->usage & 0xffffffffu);
  }
  record->create_flags = info.flags;
  record->capture_source = copyable;
  state.buffers.insert_or_assign(buffer, std::move(record));
} catch (const std::bad_alloc&) {
  state.failures().buffers_incomplete.store(true, std::memory_order_relaxed);
  state.buffers.erase(buffer);
  Untracked(state);
}

void RecordDestroyBuffer(DeviceState& state, VkBuffer buffer) {
  std::optional<std::shared_ptr<const BufferState>> record = state.buffers.pop(buffer);
  if (record && *record && (*record)->device_address != 0) {
    state.buffer_addresses.Erase((*record)->device_address, buffer);
    if (state.lifetime_tracked) {
      const BufferState& b = **record;
      state.lifetimes.AddBuffer({buffer, b.device_address, b.size, b.bound_serial, state.NextObjectId()});
    }
  }
  if (record && *record && ((*record)->usage & VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR)) {
    state.structure_storage_changes.Bump();
  }
}

void RecordBindBufferMemory(DeviceState& state, const DeviceDispatchTable& dispatch, VkDevice device, VkBuffer buffer,
                            VkDeviceMemory memory, VkDeviceSize offset) {
  std::optional<std::shared_ptr<const BufferState>> old = state.buffers.find(buffer);
  if (!old || !*old) return;  // created before the layer saw the device: unknown, left alone
  VkDeviceAddress inserted = 0;
  try {
    InjectBadAlloc(FailSite::kObjectRecord);
    auto record = std::make_shared<BufferState>(**old);
    record->bound = true;
    record->memory = memory;
    record->memory_offset = offset;
    record->bound_serial = state.NextObjectId();
    if ((record->usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) && dispatch.GetBufferDeviceAddress) {
      const VkBufferDeviceAddressInfo info{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO, nullptr, buffer};
      record->device_address = dispatch.GetBufferDeviceAddress(device, &info);
    }
    if (record->device_address != 0) {
      state.buffer_addresses.Insert(record->device_address, record->size, buffer);
      inserted = record->device_address;
    }
    const bool storage = (record->usage & VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR) != 0;
    std::shared_ptr<const BufferState> published = record;
    state.buffers.insert_or_assign(buffer, std::move(record));
    if (storage) state.structure_storage_changes.Bump();
    if (storage && state.structures_awaiting_address.load(std::memory_order_relaxed) != 0) {
      AddressStructuresOf(state, dispatch, device, *published);
    }
  } catch (const std::bad_alloc&) {
    // Kept unbound it would be reported as such: the buffer becomes unknown instead.
    state.failures().buffers_incomplete.store(true, std::memory_order_relaxed);
    if (inserted != 0) state.buffer_addresses.Erase(inserted, buffer);
    state.buffers.erase(buffer);
    state.structure_storage_changes.Bump();
    Untracked(state);
  }
}

void RecordCreateAccelerationStructure(DeviceState& state, const DeviceDispatchTable& dispatch, VkDevice device,
                                       const VkAccelerationStructureCreateInfoKHR& info,
                                       VkAccelerationStructureKHR handle) try {
  InjectBadAlloc(FailSite::kStructureRecord);
  auto record = std::make_shared<AccelerationStructureState>();
  record->handle = handle;
  record->serial = state.NextObjectId();
  state.lifetimes.StructureCreated(record->serial);
  record->buffer = info.buffer;
  record->offset = info.offset;
  record->size = info.size;
  record->type = info.type;
  record->create_flags = info.createFlags;
  std::optional<std::shared_ptr<const BufferState>> buffer = state.buffers.find(info.buffer);
  const BufferState* known = buffer && *buffer ? buffer->get() : nullptr;
  if (known) record->buffer_id = known->id;
  record->buffer_was_bound = known && known->bound;
  // The layer asks for the address only where the app itself could (the buffer is bound and has
  // SHADER_DEVICE_ADDRESS usage), so that its own call breaks no rule; a buffer bound later is asked then.
  record->address = AddressAtCreation(dispatch, device, known, *record);
  const bool awaiting = record->address == AccelerationStructureState::Address::kAwaitingBind;
  if (awaiting) state.structures_awaiting_address.fetch_add(1, std::memory_order_relaxed);
  state.acceleration_structures.insert_or_assign(handle, std::move(record));
  if (state.features.nv_ray_tracing) NoteKhrStructureKey(state, handle);
  if (!awaiting) return;
  // Bound by another thread since it was looked at, before this record was there to be found: asked now.
  std::optional<std::shared_ptr<const BufferState>> now = state.buffers.find(info.buffer);
  if (now && *now && (*now)->id == known->id && (*now)->bound) AddressStructuresOf(state, dispatch, device, **now);
} catch (const std::bad_alloc&) {
  // Unknown to the layer: its checks skip and count (a handle that is not a live structure the layer knows), and
  // the histories never record it (history_apply.cpp: Fresh).
  state.failures().structures_incomplete.store(true, std::memory_order_relaxed);
  state.acceleration_structures.erase(handle);
  Untracked(state);
}

void RecordDestroyAccelerationStructure(DeviceState& state, VkAccelerationStructureKHR handle) {
  std::optional<std::shared_ptr<const AccelerationStructureState>> record = state.acceleration_structures.pop(handle);
  if (record && *record && state.lifetime_tracked) {
    state.lifetimes.AddStructure({handle, (*record)->serial, state.NextObjectId()});
  }
  if (record && *record && (*record)->address == AccelerationStructureState::Address::kAwaitingBind) {
    state.structures_awaiting_address.fetch_sub(1, std::memory_order_relaxed);
  }
  std::unique_lock<std::mutex> lock = state.history.store.Lock();
  try {
    state.history.store.Forget(handle);  // the record is out of the index before anything is allocated
  } catch (const std::bad_alloc&) {
    ForgetFailed(state);
  }
}

void RecordMapMemory(DeviceState& state, VkDeviceMemory memory, VkDeviceSize offset, VkDeviceSize size,
                     void* host_address) {
  VkDeviceSize bytes = size;
  if (size == VK_WHOLE_SIZE) {
    const std::optional<std::shared_ptr<const MemoryState>> record = state.memories.find(memory);
    if (!record || !*record || (*record)->size < offset) return;  // extent unknown: not recorded
    bytes = (*record)->size - offset;
  }
  try {
    InjectBadAlloc(FailSite::kObjectRecord);
    state.host_mappings.Map(memory, offset, bytes, host_address);
  } catch (const std::bad_alloc&) {
    // Not recorded: a host pointer into it is then in no mapping the layer knows, and is not judged.
    state.host_mappings.Unmap(memory);
    Untracked(state);
  }
}

void RecordUnmapMemory(DeviceState& state, VkDeviceMemory memory) { state.host_mappings.Unmap(memory); }

void RecordCreateQueryPool(DeviceState& state, const VkQueryPoolCreateInfo& info, VkQueryPool pool) try {
  InjectBadAlloc(FailSite::kObjectRecord);
  state.history.query_pools.insert_or_assign(pool, QueryPoolState{info.queryType, info.queryCount});
} catch (const std::bad_alloc&) {
  state.history.query_pools.erase(pool);  // unknown: its queries' rules skip, its results are not attached
  Untracked(state);
}

void RecordDestroyQueryPool(DeviceState& state, VkQueryPool pool) {
  std::optional<QueryPoolState> record = state.history.query_pools.pop(pool);
  // Every pool that vkCmdWriteAccelerationStructuresPropertiesKHR may have written slots of (compacted sizes too,
  // not only serialization sizes): otherwise an app that makes a compaction query pool per frame leaves its slots
  // in the store for good (found by the long run's footprint, issue 14).
  if (record && record->type != VK_QUERY_TYPE_OCCLUSION && record->type != VK_QUERY_TYPE_PIPELINE_STATISTICS &&
      record->type != VK_QUERY_TYPE_TIMESTAMP) {
    std::unique_lock<std::mutex> lock = state.history.store.Lock();
    state.history.store.ForgetPool(pool);
  }
}

DeviceFeatures ParseEnabledFeatures(const VkDeviceCreateInfo& info) {
  DeviceFeatures f;
  for (auto* s = static_cast<const VkBaseInStructure*>(info.pNext); s; s = s->pNext) {
    switch (s->sType) {
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR: {
        auto* as = reinterpret_cast<const VkPhysicalDeviceAccelerationStructureFeaturesKHR*>(s);
        f.acceleration_structure = as->accelerationStructure;
        f.acceleration_structure_host_commands = as->accelerationStructureHostCommands;
        f.acceleration_structure_indirect_build = as->accelerationStructureIndirectBuild;
        f.acceleration_structure_capture_replay = as->accelerationStructureCaptureReplay;
        break;
      }
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_BUFFER_DEVICE_ADDRESS_FEATURES:
        f.buffer_device_address |=
            reinterpret_cast<const VkPhysicalDeviceBufferDeviceAddressFeatures*>(s)->bufferDeviceAddress;
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_BUFFER_DEVICE_ADDRESS_FEATURES_EXT:
        f.buffer_device_address |=
            reinterpret_cast<const VkPhysicalDeviceBufferDeviceAddressFeaturesEXT*>(s)->bufferDeviceAddress;
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES:
        f.buffer_device_address |= reinterpret_cast<const VkPhysicalDeviceVulkan12Features*>(s)->bufferDeviceAddress;
        break;
      case VK_STRUCTURE_TYPE_DEVICE_GROUP_DEVICE_CREATE_INFO: {
        const uint32_t count = reinterpret_cast<const VkDeviceGroupDeviceCreateInfo*>(s)->physicalDeviceCount;
        f.physical_device_count = count > 0 ? count : 1;
        break;
      }
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR:
        f.ray_query = reinterpret_cast<const VkPhysicalDeviceRayQueryFeaturesKHR*>(s)->rayQuery;
        break;
      case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR:
        f.ray_tracing_pipeline =
            reinterpret_cast<const VkPhysicalDeviceRayTracingPipelineFeaturesKHR*>(s)->rayTracingPipeline;
        break;
      default:
        break;
    }
  }
  return f;
}

}  // namespace asval
