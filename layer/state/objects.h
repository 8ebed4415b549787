#pragma once
// Shadow records of the objects the acceleration-structure rules need. Each record is immutable once it is
// in a map: a change (binding a buffer's memory, say) publishes a new record, so readers on other threads
// never see a half-written object and need no lock of their own.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

namespace asval {

struct MemoryState {
  VkDeviceMemory handle = VK_NULL_HANDLE;
  VkDeviceSize size = 0;
  uint32_t type_index = 0;
  VkMemoryPropertyFlags property_flags = 0;
  VkMemoryAllocateFlags allocate_flags = 0;  // from VkMemoryAllocateFlagsInfo (DEVICE_ADDRESS_BIT matters)
  // Allocated with multiple instances (a device group): VkMemoryAllocateFlagsInfo::deviceMask with more than
  // one bit, or, without DEVICE_MASK_BIT, a MULTI_INSTANCE heap on a device over several physical devices.
  bool multi_instance = false;
  // The layer may bind a buffer of its own to it (the capture's copies read through one: layer/capture's
  // MemoryAliases): not protected, not a dedicated allocation, not exported or imported, and nothing else in the
  // allocation's pNext chain that the layer does not know (VUID-vkBindBufferMemory-memory-01508, 01509, 02726,
  // 02985, None-01899).
  bool layer_may_bind = false;
  // VkMemoryDedicatedAllocateInfo::buffer: the one buffer that can ever be bound to it.
  VkBuffer dedicated_buffer = VK_NULL_HANDLE;
};

struct BufferState {
  VkBuffer handle = VK_NULL_HANDLE;
  // Unique per device for the buffer's lifetime (handle values are reused after vkDestroyBuffer): what a
  // structure holds to know that the buffer it finds under its handle is still the one it was created on.
  uint64_t id = 0;
  VkDeviceSize size = 0;
  VkBufferUsageFlags usage = 0;
  VkBufferCreateFlags create_flags = 0;
  // Created with TRANSFER_SRC usage, the app's or added by the layer (vkCreateBuffer): the capture may copy from it
  // where it is bound to a dedicated allocation (elsewhere it copies through a buffer of its own over the memory).
  bool capture_source = false;
  // Binding, set by vkBindBufferMemory(2); a sparse buffer is never "bound" this way.
  bool bound = false;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkDeviceSize memory_offset = 0;
  // The memory it was bound to was freed (memory is then VK_NULL_HANDLE: the handle value may be reused).
  bool memory_freed = false;
  // Queried by the layer itself at bind time when the usage has SHADER_DEVICE_ADDRESS; 0 otherwise.
  VkDeviceAddress device_address = 0;
  // DeviceState::NextObjectId() when it was bound: a submission made before holds no address of it that it could
  // have found through another buffer since destroyed (in_flight.h: an address is not an identity).
  uint64_t bound_serial = 0;

  bool Contains(VkDeviceSize offset, VkDeviceSize bytes) const { return offset <= size && bytes <= size - offset; }
};

struct AccelerationStructureState {
  VkAccelerationStructureKHR handle = VK_NULL_HANDLE;
  // DeviceState::NextObjectId() at creation: a submission made before it cannot name it (handles are reused).
  uint64_t serial = 0;
  VkBuffer buffer = VK_NULL_HANDLE;
  uint64_t buffer_id = 0;  // BufferState::id of that buffer when the structure was created (0: unknown buffer)
  VkDeviceSize offset = 0;
  VkDeviceSize size = 0;
  VkAccelerationStructureTypeKHR type = VK_ACCELERATION_STRUCTURE_TYPE_GENERIC_KHR;
  VkAccelerationStructureCreateFlagsKHR create_flags = 0;
  VkDeviceAddress device_address = 0;  // asked of the driver by the layer where the app itself could ask
  // What the layer knows of the structure's address (instance references are judged against the known ones):
  enum class Address : uint8_t {
    kKnown,         // device_address
    kNone,          // it has none: its buffer lacks SHADER_DEVICE_ADDRESS usage, so no instance can reference it
    kAwaitingBind,  // its buffer was not bound when it was created: asked when the buffer is bound, none until then
    kUnknown,       // it may have one the layer does not know (its buffer unknown or sparse, the query unavailable)
  };
  Address address = Address::kUnknown;
  // The buffer was bound to memory when the structure was created. A binding never goes away, so the
  // bound-memory rules (pInfos-03707/03708) need no buffer lookup for such a structure.
  bool buffer_was_bound = false;
};

// A VK_NV_ray_tracing structure: created with its build parameters (VkAccelerationStructureInfoNV), then bound to
// memory by vkBindAccelerationStructureMemoryNV (it has no buffer). Its build history shares the KHR structures'
// store, keyed by the handle's value (history_key below).
struct NvStructureState {
  VkAccelerationStructureNV handle = VK_NULL_HANDLE;
  uint64_t serial = 0;  // DeviceState::NextObjectId() at creation
  // What each geometry of the creation info holds room for (dst-02488: a build may not exceed it).
  struct GeometryRoom {
    VkGeometryTypeKHR type = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
    uint32_t vertices = 0;  // triangles: vertexCount
    uint32_t indices = 0;   // triangles: indexCount (0 without indices)
    uint32_t aabbs = 0;     // aabbs: numAABBs
  };
  VkAccelerationStructureTypeNV type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_NV;
  VkBuildAccelerationStructureFlagsNV flags = 0;
  uint32_t instance_count = 0;
  std::vector<GeometryRoom> geometries;
  VkDeviceSize compacted_size = 0;
  // vkGetAccelerationStructureMemoryRequirementsNV's sizes, asked by the layer at creation; 0 when unknown.
  VkDeviceSize object_size = 0;
  VkDeviceSize build_scratch_size = 0;
  VkDeviceSize update_scratch_size = 0;
  // Set by vkBindAccelerationStructureMemoryNV.
  bool bound = false;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkDeviceSize memory_offset = 0;
  // The handle's value also names a live VkAccelerationStructureKHR (handles of different types may share values):
  // its operations are then kept out of the build history, and the rules that need it skipped and counted.
  bool shares_key = false;
};

}  // namespace asval
