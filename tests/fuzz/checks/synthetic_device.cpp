#include "synthetic_device.h"

#include <optional>

#include "state_tracker.h"
#include "vk_struct_chain.h"

namespace asval::fuzz {

namespace {

template <typename H>
H Handle(uint64_t value) {
  return reinterpret_cast<H>(value);
}

// What the fake driver answers for the current input (one input at a time: the fuzz target is single-threaded).
struct FakeDriver {
  VkDeviceAddress next_address = 0;  // the answer to the next address query
  uint32_t bytes_per_primitive = 64;
  uint32_t scratch_per_primitive = 32;
  bool zero_scratch = false;
  uint32_t format_mask = ~0u;
};
FakeDriver g_driver;

VKAPI_ATTR VkDeviceAddress VKAPI_CALL FakeBufferAddress(VkDevice, const VkBufferDeviceAddressInfo*) {
  return g_driver.next_address;
}

VKAPI_ATTR VkDeviceAddress VKAPI_CALL FakeStructureAddress(VkDevice,
                                                           const VkAccelerationStructureDeviceAddressInfoKHR*) {
  return g_driver.next_address;
}

// The formats the spec makes mandatory for acceleration-structure vertex buffers, each dropped when the input
// says (a driver that lacks one).
VKAPI_ATTR void VKAPI_CALL FakeFormatProperties(VkPhysicalDevice, VkFormat format, VkFormatProperties* properties) {
  static const VkFormat kVertexFormats[] = {VK_FORMAT_R32G32_SFLOAT,       VK_FORMAT_R32G32B32_SFLOAT,
                                            VK_FORMAT_R16G16_SFLOAT,       VK_FORMAT_R16G16B16A16_SFLOAT,
                                            VK_FORMAT_R16G16_SNORM,        VK_FORMAT_R16G16B16A16_SNORM,
                                            VK_FORMAT_R8G8B8A8_SNORM,      VK_FORMAT_A2B10G10R10_UNORM_PACK32};
  *properties = VkFormatProperties{};
  for (uint32_t k = 0; k < sizeof(kVertexFormats) / sizeof(kVertexFormats[0]); ++k) {
    if (format == kVertexFormats[k] && (g_driver.format_mask >> k & 1)) {
      properties->bufferFeatures = VK_FORMAT_FEATURE_ACCELERATION_STRUCTURE_VERTEX_BUFFER_BIT_KHR;
    }
  }
}

// Reads every geometry and count the layer passes, as a driver would (a short array is a sanitizer report), and
// answers sizes that grow with the counts.
VKAPI_ATTR void VKAPI_CALL FakeBuildSizes(VkDevice, VkAccelerationStructureBuildTypeKHR,
                                          const VkAccelerationStructureBuildGeometryInfoKHR* info,
                                          const uint32_t* counts,
                                          VkAccelerationStructureBuildSizesInfoKHR* sizes) {
  uint64_t primitives = 0;
  for (uint32_t j = 0; j < info->geometryCount; ++j) {
    const VkAccelerationStructureGeometryKHR* g = info->pGeometries ? &info->pGeometries[j] : info->ppGeometries[j];
    primitives += counts[j] + (g->geometryType == VK_GEOMETRY_TYPE_AABBS_KHR ? 1 : 0);
  }
  sizes->accelerationStructureSize = 256 + primitives * g_driver.bytes_per_primitive;
  sizes->buildScratchSize = g_driver.zero_scratch ? 0 : 128 + primitives * g_driver.scratch_per_primitive;
  sizes->updateScratchSize = g_driver.zero_scratch ? 0 : primitives * g_driver.scratch_per_primitive / 2;
}

// Limits as drivers report them, and the values that make the rules' arithmetic interesting (0: not reported).
uint32_t ChooseLimit(ByteSource& in, uint32_t typical) {
  switch (in.Below(6)) {
    case 0: return 0;
    case 1: return 1 + in.Below(4);
    case 2: return in.U32();
    case 3: return ~0u;
    default: return typical;
  }
}

VkBufferUsageFlags ChooseUsage(ByteSource& in) {
  static const VkBufferUsageFlags kBits[] = {VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR,
                                             VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR,
                                             VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
                                             VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                             VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                             VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                             VK_BUFFER_USAGE_SHADER_BINDING_TABLE_BIT_KHR};
  const uint8_t pick = in.U8();
  VkBufferUsageFlags usage = 0;
  for (uint32_t k = 0; k < 7; ++k) {
    if (pick >> k & 1) usage |= kBits[k];
  }
  if (pick & 0x80) usage |= in.U32();  // bits of later extensions too
  return usage;
}

}  // namespace

HostArena::HostArena(uint64_t seed) : bytes_(kBytes) {
  uint64_t x = seed | 1;
  for (size_t k = 0; k < bytes_.size(); k += 8) {  // xorshift: cheap bytes that are not all alike
    x ^= x << 13;
    x ^= x >> 7;
    x ^= x << 17;
    for (size_t b = 0; b < 8; ++b) bytes_[k + b] = static_cast<uint8_t>(x >> (8 * b));
  }
}

uint8_t* HostArena::Place(ByteSource& in, size_t bytes) {
  const size_t room = bytes_.size() - bytes + 1;
  size_t offset = in.U16() % room;
  if (in.Bit()) offset &= ~size_t{15};  // often aligned, as apps do
  return bytes_.data() + offset;
}

SyntheticDevice::SyntheticDevice(ByteSource& in)
    : state_(std::make_unique<DeviceState>()), device_(Handle<VkDevice>(0xd0)), arena_(in.U64()) {
  dispatch_.GetBufferDeviceAddress = &FakeBufferAddress;
  dispatch_.GetAccelerationStructureDeviceAddressKHR = &FakeStructureAddress;
  DecodeLimits(in);
  CreateMemories(in);
  CreateBuffers(in);
  CreateStructures(in);
  CreatePoolsAndCommandBuffers(in);
  Teardowns(in);
}

void SyntheticDevice::DecodeLimits(ByteSource& in) {
  DeviceFeatures& f = state_->features;
  uint8_t features = in.U8();
  if (!in.OneIn(4)) features |= 0x7f;  // mostly all on, as a ray-tracing app enables
  f.acceleration_structure = features & 1;
  f.acceleration_structure_host_commands = features & 2;
  f.acceleration_structure_indirect_build = features & 4;
  f.acceleration_structure_capture_replay = features & 8;
  f.buffer_device_address = features & 16;
  f.ray_query = features & 32;
  f.ray_tracing_pipeline = features & 64;
  f.physical_device_count = 1 + in.Below(4);
  state_->history_tracked = !in.OneIn(8);

  VkPhysicalDeviceAccelerationStructurePropertiesKHR& limits = state_->properties.acceleration_structure;
  limits.maxGeometryCount = ChooseLimit(in, (1u << 24) - 1);
  limits.maxInstanceCount = ChooseLimit(in, (1u << 24) - 1);
  limits.maxPrimitiveCount = ChooseLimit(in, (1u << 29) - 1);
  const uint32_t alignments[] = {0, 1, 16, 128, 256, 4096};
  limits.minAccelerationStructureScratchOffsetAlignment = in.Pick(alignments);

  VkPhysicalDeviceMemoryProperties& memory = state_->properties.memory;
  memory.memoryHeapCount = 1 + in.Below(2);
  for (uint32_t h = 0; h < memory.memoryHeapCount; ++h) {
    memory.memoryHeaps[h].size = VkDeviceSize{1} << 32;
    memory.memoryHeaps[h].flags = in.U8() & (VK_MEMORY_HEAP_DEVICE_LOCAL_BIT | VK_MEMORY_HEAP_MULTI_INSTANCE_BIT);
  }
  memory.memoryTypeCount = 1 + in.Below(4);
  for (uint32_t t = 0; t < memory.memoryTypeCount; ++t) {
    memory.memoryTypes[t].propertyFlags = in.U8() & 0x3f;  // device-local, host-visible/coherent/cached, ...
    memory.memoryTypes[t].heapIndex = in.Below(memory.memoryHeapCount + 1);  // one past: a broken driver's answer
  }

  g_driver = FakeDriver{};
  g_driver.bytes_per_primitive = in.U8();
  g_driver.scratch_per_primitive = in.U8();
  g_driver.zero_scratch = in.OneIn(8);
  g_driver.format_mask = in.OneIn(4) ? in.U8() : 0xffu;
  if (!in.OneIn(8)) state_->build_sizes.Init(device_, &FakeBuildSizes);  // else: sizes never known
  state_->format_features.Init(Handle<VkPhysicalDevice>(0x77), &FakeFormatProperties);
}

void SyntheticDevice::CreateMemories(ByteSource& in) {
  const uint32_t count = 1 + in.Below(4);
  for (uint32_t k = 0; k < count; ++k) {
    VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
    flags.flags = in.U8() & 7;
    flags.deviceMask = in.U8();
    VkMemoryAllocateInfo info{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, in.Bit() ? &flags : nullptr};
    info.allocationSize = in.Bit() ? VkDeviceSize{1} << 24 : 1 + in.U32();
    info.memoryTypeIndex = in.Below(5);  // sometimes past memoryTypeCount
    const VkDeviceMemory memory = Handle<VkDeviceMemory>(NextHandle());
    RecordAllocateMemory(*state_, info, memory);
    memories_.push_back(memory);
  }
}

VkDeviceAddress SyntheticDevice::ChooseBufferAddress(ByteSource& in, VkDeviceSize size) {
  switch (in.Below(8)) {
    case 0: return 0;  // a driver that gave no address
    case 1:            // the same bytes as an earlier buffer (a whole-allocation buffer, aliasing)
      if (!spans_.empty()) return spans_[in.Below(static_cast<uint32_t>(spans_.size()))].base;
      break;
    case 2:  // overlapping an earlier buffer part-way
      if (!spans_.empty()) {
        const Span& s = spans_[in.Below(static_cast<uint32_t>(spans_.size()))];
        return s.base + (s.size ? in.U32() % s.size : 0);
      }
      break;
    case 3: return ~VkDeviceAddress{0} - size + 1 - (in.U16() & 0xff0);  // at the top of the address space
    case 4: return in.U64() & ~VkDeviceAddress{0xf};
    default: break;
  }
  const VkDeviceAddress base = next_packed_;  // side by side, as a sub-allocator places them
  next_packed_ += (size + 0xff) & ~VkDeviceSize{0xff};
  return base;
}

void SyntheticDevice::CreateBuffers(ByteSource& in) {
  const uint32_t count = in.Below(9);
  for (uint32_t k = 0; k < count; ++k) {
    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    const VkDeviceSize sizes[] = {256, 4096, VkDeviceSize{1} << 20, VkDeviceSize{1} + in.U8(),
                                  VkDeviceSize{1} + in.U32(), in.U64() >> in.Below(64)};
    info.size = in.Pick(sizes);
    if (info.size == 0) info.size = 1;
    info.usage = ChooseUsage(in);
    if (in.OneIn(4)) info.flags = in.U8() & 0x1f;  // sparse binding, residency, aliased, protected, capture replay
    BufferUsageFlags2CreateInfo usage2{kBufferUsageFlags2CreateInfo, nullptr, (uint64_t{in.U32()} << 32) | info.usage};
    if (in.OneIn(8)) info.pNext = &usage2;
    const VkBuffer buffer = Handle<VkBuffer>(NextHandle());
    RecordCreateBuffer(*state_, info, buffer, in.Bit());
    buffers_.push_back(buffer);
    if (in.OneIn(5)) continue;  // never bound
    VkDeviceMemory memory = memories_[in.Below(static_cast<uint32_t>(memories_.size()))];
    if (in.OneIn(8)) memory = Handle<VkDeviceMemory>(0xbad000 + in.U8());  // memory the layer never saw
    const VkDeviceSize offset = in.Bit() ? 0 : VkDeviceSize{in.U16()} << in.Below(12);
    g_driver.next_address = ChooseBufferAddress(in, info.size);
    RecordBindBufferMemory(*state_, dispatch_, device_, buffer, memory, offset);
    if (g_driver.next_address != 0) spans_.push_back(Span{g_driver.next_address, info.size});
  }
}

void SyntheticDevice::CreateStructures(ByteSource& in) {
  const uint32_t count = in.Below(9);
  for (uint32_t k = 0; k < count; ++k) {
    VkAccelerationStructureCreateInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
    info.buffer = buffers_.empty() || in.OneIn(8) ? Handle<VkBuffer>(0xb0f000 + in.U8())
                                                  : buffers_[in.Below(static_cast<uint32_t>(buffers_.size()))];
    const VkAccelerationStructureTypeKHR types[] = {
        VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
        VK_ACCELERATION_STRUCTURE_TYPE_GENERIC_KHR, in.AnyEnum<VkAccelerationStructureTypeKHR>()};
    info.type = in.Pick(types);
    info.createFlags = in.OneIn(4) ? in.U32() : 0;
    info.offset = in.Bit() ? 0 : VkDeviceSize{in.U16()} << (in.Bit() ? 8 : 0);
    const VkDeviceSize sizes[] = {256, 4096, 65536, VkDeviceSize{1} << 20, in.U32(), in.U64()};
    info.size = in.Pick(sizes);
    VkDeviceAddress base = 0;  // the fake driver places it at its offset in its buffer, or anywhere
    std::optional<std::shared_ptr<const BufferState>> buffer = state_->buffers.find(info.buffer);
    if (buffer && *buffer) base = (*buffer)->device_address;
    g_driver.next_address = in.OneIn(4) ? in.U64() : base + info.offset;
    const VkAccelerationStructureKHR handle = Handle<VkAccelerationStructureKHR>(NextHandle());
    RecordCreateAccelerationStructure(*state_, dispatch_, device_, info, handle);
    structures_.push_back(handle);
    if (g_driver.next_address != 0) spans_.push_back(Span{g_driver.next_address, info.size});
  }
}

void SyntheticDevice::CreatePoolsAndCommandBuffers(ByteSource& in) {
  const uint32_t pools = in.Below(3);
  for (uint32_t k = 0; k < pools; ++k) {
    VkQueryPoolCreateInfo info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    const VkQueryType types[] = {VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR,
                                 VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR,
                                 VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SIZE_KHR,
                                 VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_BOTTOM_LEVEL_POINTERS_KHR,
                                 VK_QUERY_TYPE_OCCLUSION, in.AnyEnum<VkQueryType>()};
    info.queryType = in.Pick(types);
    info.queryCount = in.Bit() ? in.U8() : in.U32();
    const VkQueryPool pool = Handle<VkQueryPool>(NextHandle());
    RecordCreateQueryPool(*state_, info, pool);
    query_pools_.push_back(pool);
  }
  const uint32_t command_pools = in.Below(3);
  for (uint32_t k = 0; k < command_pools; ++k) {
    const VkCommandPool pool = Handle<VkCommandPool>(NextHandle());
    state_->command_buffers.CreatePool(pool, in.U8() & 7);  // transient, reset, protected
    VkCommandBufferAllocateInfo info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    info.commandPool = pool;
    info.level = in.Bit() ? VK_COMMAND_BUFFER_LEVEL_PRIMARY : VK_COMMAND_BUFFER_LEVEL_SECONDARY;
    info.commandBufferCount = 1;
    const VkCommandBuffer cb = Handle<VkCommandBuffer>(NextHandle());
    state_->command_buffers.Allocate(info, &cb);
    command_buffers_.push_back(cb);
  }
}

// Objects that go away after others were created on them: structures on destroyed buffers or freed memory, handles
// of destroyed structures, mappings into the arena.
void SyntheticDevice::Teardowns(ByteSource& in) {
  const uint32_t count = in.Below(4);
  for (uint32_t k = 0; k < count; ++k) {
    switch (in.Below(4)) {
      case 0:
        if (!buffers_.empty()) RecordDestroyBuffer(*state_, buffers_[in.Below(static_cast<uint32_t>(buffers_.size()))]);
        break;
      case 1: RecordFreeMemory(*state_, memories_[in.Below(static_cast<uint32_t>(memories_.size()))]); break;
      case 2:
        if (!structures_.empty()) {
          RecordDestroyAccelerationStructure(*state_, structures_[in.Below(static_cast<uint32_t>(structures_.size()))]);
        }
        break;
      default: break;
    }
  }
  const uint32_t mappings = in.Below(3);
  for (uint32_t k = 0; k < mappings; ++k) {
    const size_t bytes = 1 + in.U16() % HostArena::kBytes;
    const VkDeviceSize size = in.OneIn(4) ? VK_WHOLE_SIZE : bytes;
    const VkDeviceMemory memory = memories_[in.Below(static_cast<uint32_t>(memories_.size()))];
    const VkDeviceSize offset = in.U16();
    RecordMapMemory(*state_, memory, offset, size, arena_.Place(in, bytes));
  }
}

VkAccelerationStructureKHR SyntheticDevice::Structure(ByteSource& in) const {
  switch (in.Below(8)) {
    case 0: return VK_NULL_HANDLE;
    case 1: return Handle<VkAccelerationStructureKHR>(in.Bit() ? 0xa5a5 + in.U8() : in.U64());  // never seen
    default:
      if (structures_.empty()) return VK_NULL_HANDLE;
      return structures_[in.Below(static_cast<uint32_t>(structures_.size()))];
  }
}

VkCommandBuffer SyntheticDevice::CommandBuffer(ByteSource& in) const {
  if (command_buffers_.empty() || in.OneIn(4)) return Handle<VkCommandBuffer>(0xcb00 + in.U8());
  return command_buffers_[in.Below(static_cast<uint32_t>(command_buffers_.size()))];
}

VkQueryPool SyntheticDevice::QueryPool(ByteSource& in) const {
  if (query_pools_.empty() || in.OneIn(4)) return in.Bit() ? VK_NULL_HANDLE : Handle<VkQueryPool>(0x9900 + in.U8());
  return query_pools_[in.Below(static_cast<uint32_t>(query_pools_.size()))];
}

VkDeferredOperationKHR SyntheticDevice::DeferredOperation(ByteSource& in) const {
  return in.OneIn(3) ? Handle<VkDeferredOperationKHR>(0xdef0 + in.Below(2)) : VK_NULL_HANDLE;
}

VkDeviceAddress SyntheticDevice::DeviceAddress(ByteSource& in) const {
  const uint32_t how = in.Below(8);
  if (how == 0) return 0;
  if (how == 1 || spans_.empty()) return in.OneIn(2) ? in.U64() : in.U16();
  const Span& s = spans_[in.Below(static_cast<uint32_t>(spans_.size()))];
  const uint32_t alignments[] = {1, 2, 4, 8, 16, 256};
  switch (how) {
    case 2: return s.base + s.size - in.Below(64);                  // across the end
    case 3: return s.base + s.size + in.Below(64);                  // just past it
    case 4: return s.base - 1 - in.Below(64);                       // just before it
    default: {                                                      // inside, variously aligned
      const VkDeviceSize offset = s.size ? in.U32() % s.size : 0;
      return (s.base + offset) & ~VkDeviceAddress{in.Pick(alignments) - 1};
    }
  }
}

}  // namespace asval::fuzz
