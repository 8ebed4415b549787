#include "build_call.h"

#include <algorithm>
#include <cstddef>
#include <cstring>

#include "vk_struct_chain.h"

namespace asval::fuzz {

namespace {

// Infos of other types hold this many geometries at most (their arrays are full: the layer may walk them all).
constexpr uint32_t kMaxFullGeometries = 12;

const char* FunctionOf(BuildCommandKind kind) {
  switch (kind) {
    case BuildCommandKind::kCmdBuild: return "vkCmdBuildAccelerationStructuresKHR";
    case BuildCommandKind::kCmdBuildIndirect: return "vkCmdBuildAccelerationStructuresIndirectKHR";
    case BuildCommandKind::kHostBuild: break;
  }
  return "vkBuildAccelerationStructuresKHR";
}

VkAccelerationStructureTypeKHR ChooseType(ByteSource& in) {
  switch (in.Below(6)) {
    case 0: return VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
    case 1: return VK_ACCELERATION_STRUCTURE_TYPE_GENERIC_KHR;
    case 2: return in.AnyEnum<VkAccelerationStructureTypeKHR>();
    default: return VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  }
}

VkGeometryTypeKHR ChooseGeometryType(ByteSource& in, VkAccelerationStructureTypeKHR info_type) {
  if (in.OneIn(8)) {
    return in.Bit() ? in.AnyEnum<VkGeometryTypeKHR>() : static_cast<VkGeometryTypeKHR>(in.Below(4));
  }
  if (info_type == VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR && !in.OneIn(4)) return VK_GEOMETRY_TYPE_INSTANCES_KHR;
  return in.Bit() ? VK_GEOMETRY_TYPE_TRIANGLES_KHR : VK_GEOMETRY_TYPE_AABBS_KHR;
}

VkFormat ChooseVertexFormat(ByteSource& in) {
  static const VkFormat kFormats[] = {
      VK_FORMAT_R32G32B32_SFLOAT,    VK_FORMAT_R32G32_SFLOAT,         VK_FORMAT_R16G16B16A16_SFLOAT,
      VK_FORMAT_R16G16_SFLOAT,       VK_FORMAT_R16G16_SNORM,          VK_FORMAT_R16G16B16A16_SNORM,
      VK_FORMAT_R8G8B8A8_SNORM,      VK_FORMAT_A2B10G10R10_UNORM_PACK32, VK_FORMAT_R64G64B64_SFLOAT,
      VK_FORMAT_R16G16B16A16_UNORM,  VK_FORMAT_UNDEFINED};
  if (in.OneIn(12)) return in.AnyEnum<VkFormat>();
  return in.Pick(kFormats);
}

VkIndexType ChooseIndexType(ByteSource& in) {
  switch (in.Below(6)) {
    case 0: return VK_INDEX_TYPE_UINT16;
    case 1: return VK_INDEX_TYPE_UINT32;
    case 2: return VK_INDEX_TYPE_UINT8_EXT;
    case 3: return in.AnyEnum<VkIndexType>();
    default: return VK_INDEX_TYPE_NONE_KHR;
  }
}

// Structures the headers know, none of which belongs where the chains put them, or some of them in the right place.
VkStructureType KnownChainType(ByteSource& in) {
  static const VkStructureType kKnown[] = {
      VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_MOTION_TRIANGLES_DATA_NV,
      VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_MOTION_INFO_NV,
      VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_TRIANGLES_OPACITY_MICROMAP_EXT,
      VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR,
      VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR,
      VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO,
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR,
      kBufferUsageFlags2CreateInfo};
  return in.Pick(kKnown);
}

}  // namespace

BuildCall::BuildCall(ByteSource& in, SyntheticDevice& device, BuildCommandKind kind)
    : device_(device), host_(kind == BuildCommandKind::kHostBuild), command_{kind, FunctionOf(kind)} {
  const uint32_t count = in.OneIn(16) ? 60 + in.Below(12) : in.Below(5);  // past the per-thread hints now and then
  infos_.resize(count);
  arrays_.resize(count);
  range_pointers_.resize(count);
  max_count_pointers_.resize(count);
  indirect_addresses_.resize(count);
  indirect_strides_.resize(count);
  for (uint32_t i = 0; i < count; ++i) DecodeInfo(in, i);

  command_.device = device.device();
  if (host_) {
    command_.deferred_operation = device.DeferredOperation(in);
  } else {
    command_.command_buffer = device.CommandBuffer(in);
  }
  command_.info_count = count;
  command_.infos = infos_.data();
  if (kind == BuildCommandKind::kCmdBuildIndirect) {
    command_.indirect_addresses = indirect_addresses_.data();
    command_.indirect_strides = indirect_strides_.data();
    command_.max_primitive_counts = in.OneIn(32) ? nullptr : max_count_pointers_.data();
  } else {
    command_.ranges = in.OneIn(32) ? nullptr : range_pointers_.data();
  }
}

void BuildCall::DecodeInfo(ByteSource& in, uint32_t i) {
  VkAccelerationStructureBuildGeometryInfoKHR& info = infos_[i];
  info = VkAccelerationStructureBuildGeometryInfoKHR{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  if (in.OneIn(16)) info.sType = in.AnyEnum<VkStructureType>();
  info.pNext = Chain(in);
  info.type = ChooseType(in);
  info.flags = in.U8() & 0x1f;
  if (in.OneIn(4)) info.flags |= VK_BUILD_ACCELERATION_STRUCTURE_MOTION_BIT_NV;
  if (in.OneIn(4)) info.flags |= in.U32();  // micromap bits and bits newer than the headers
  switch (in.Below(6)) {
    case 0:
    case 1: info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR; break;
    case 2: info.mode = in.AnyEnum<VkBuildAccelerationStructureModeKHR>(); break;
    default: info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR; break;
  }
  info.srcAccelerationStructure = device_.Structure(in);
  info.dstAccelerationStructure = device_.Structure(in);

  uint32_t length = 0;
  info.geometryCount = DecodeGeometryCount(in, info, &length);
  InfoArrays& a = arrays_[i];
  a.geometries.resize(length);
  a.ranges.resize(length);
  a.max_counts.resize(length);
  a.pointers.resize(length);
  for (uint32_t j = 0; j < length; ++j) {
    DecodeGeometry(in, info, a.geometries[j], a.ranges[j]);
    switch (in.Below(4)) {
      case 0: a.max_counts[j] = in.U32(); break;
      case 1: a.max_counts[j] = a.ranges[j].primitiveCount; break;
      default: a.max_counts[j] = in.Below(64); break;
    }
    a.pointers[j] = in.OneIn(32) ? nullptr : &a.geometries[j];
  }
  switch (in.Below(8)) {
    case 5:
    case 6: info.ppGeometries = a.pointers.data(); break;
    case 7:  // both, or neither
      if (in.Bit()) {
        info.pGeometries = a.geometries.data();
        info.ppGeometries = a.pointers.data();
      }
      break;
    default: info.pGeometries = a.geometries.data(); break;
  }
  range_pointers_[i] = length != 0 && in.OneIn(32) ? nullptr : a.ranges.data();
  max_count_pointers_[i] = length != 0 && in.OneIn(32) ? nullptr : a.max_counts.data();

  if (host_) {
    info.scratchData.hostAddress = in.OneIn(6) ? nullptr : device_.arena().Place(in, 1);
  } else {
    info.scratchData.deviceAddress = device_.DeviceAddress(in);
  }
  indirect_addresses_[i] = device_.DeviceAddress(in);
  const uint32_t strides[] = {12, 16, 0, 4, 13, 32, 0x7fffffff};
  indirect_strides_[i] = in.Pick(strides);
}

// A bottom-level info past maxGeometryCount is invalid as a whole: the layer must not walk its geometries, and the
// array behind it may be shorter than the count. Every other array holds as many geometries as the count says.
uint32_t BuildCall::DecodeGeometryCount(ByteSource& in, const VkAccelerationStructureBuildGeometryInfoKHR& info,
                                        uint32_t* length) {
  const uint32_t limit = device_.state().properties.acceleration_structure.maxGeometryCount;
  const bool may_be_short = info.type == VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR && limit != 0 && limit != ~0u;
  uint32_t count = 0;
  switch (in.Below(8)) {
    case 0: count = 0; break;
    case 1: count = in.Below(kMaxFullGeometries + 1); break;
    case 2:
      if (may_be_short) {
        count = limit + 1;
        if (in.Bit()) count += in.U32() % (~0u - limit);
      } else {
        count = 1;
      }
      break;
    case 3: count = limit <= kMaxFullGeometries ? limit : 1; break;
    default: count = 1 + in.Below(3); break;
  }
  *length = count;
  if (may_be_short && count > limit && (count > kMaxFullGeometries || in.Bit())) {
    *length = 1 + in.Below(std::min(count, 4u));
  }
  short_arrays_ |= *length < count;
  return count;
}

void BuildCall::DecodeRange(ByteSource& in, VkAccelerationStructureBuildRangeInfoKHR& range) {
  if (host_) {  // small: the host inputs are placed with room for all of it
    range.primitiveCount = in.OneIn(4) ? 0 : in.Below(65);
    range.primitiveOffset = in.Below(257);
    if (in.Bit()) range.primitiveOffset &= ~15u;
    range.firstVertex = in.Below(65);
    range.transformOffset = in.Below(257);
    return;
  }
  switch (in.Below(5)) {
    case 0: range.primitiveCount = 0; break;
    case 1: range.primitiveCount = in.U16(); break;
    case 2: range.primitiveCount = in.U32(); break;
    default: range.primitiveCount = in.Below(256); break;
  }
  range.primitiveOffset = in.Bit() ? in.Below(4096) & ~3u : in.U32();
  range.firstVertex = in.Bit() ? in.Below(64) : in.U32();
  range.transformOffset = in.Bit() ? 16 * in.Below(16) : in.U32();
}

void BuildCall::DecodeGeometry(ByteSource& in, const VkAccelerationStructureBuildGeometryInfoKHR& info,
                               VkAccelerationStructureGeometryKHR& g, VkAccelerationStructureBuildRangeInfoKHR& range) {
  g = VkAccelerationStructureGeometryKHR{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  if (in.OneIn(16)) g.sType = in.AnyEnum<VkStructureType>();
  g.pNext = Chain(in);
  g.geometryType = ChooseGeometryType(in, info.type);
  g.flags = in.OneIn(8) ? in.U32() : in.U8() & 3u;
  DecodeRange(in, range);
  switch (g.geometryType) {
    case VK_GEOMETRY_TYPE_TRIANGLES_KHR: {
      VkAccelerationStructureGeometryTrianglesDataKHR& t = g.geometry.triangles;
      t.sType = in.OneIn(16) ? in.AnyEnum<VkStructureType>()
                             : VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
      t.pNext = Chain(in);
      t.vertexFormat = ChooseVertexFormat(in);
      const VkDeviceSize strides[] = {12, 16, 8, 6, 24, 0, 13, 64};
      t.vertexStride = in.Pick(strides);
      if (!host_ && in.OneIn(8)) t.vertexStride = in.Bit() ? in.U32() : in.U64();
      t.maxVertex = host_ ? in.Below(513) : in.Bit() ? in.Below(1024) : in.U32();
      t.indexType = ChooseIndexType(in);
      if (!host_) {
        t.vertexData = Address(in);
        t.indexData = Address(in);
        t.transformData = Address(in);
      }
      break;
    }
    case VK_GEOMETRY_TYPE_AABBS_KHR: {
      VkAccelerationStructureGeometryAabbsDataKHR& a = g.geometry.aabbs;
      a.sType = in.OneIn(16) ? in.AnyEnum<VkStructureType>()
                             : VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_AABBS_DATA_KHR;
      a.pNext = Chain(in);
      const VkDeviceSize strides[] = {24, 32, 0, 8, 23, 64};
      a.stride = in.Pick(strides);
      if (!host_ && in.OneIn(8)) a.stride = in.U64();
      if (!host_) a.data = Address(in);
      break;
    }
    case VK_GEOMETRY_TYPE_INSTANCES_KHR: {
      VkAccelerationStructureGeometryInstancesDataKHR& d = g.geometry.instances;
      d.sType = in.OneIn(16) ? in.AnyEnum<VkStructureType>()
                             : VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
      d.pNext = Chain(in);
      d.arrayOfPointers = in.Bit() ? VK_TRUE : VK_FALSE;
      if (!host_ && in.OneIn(8)) d.arrayOfPointers = in.U32();  // neither VK_TRUE nor VK_FALSE
      if (!host_) d.data = Address(in);
      break;
    }
    default: {  // a type the layer does not know: its union is bytes, never pointers the layer may follow
      uint8_t bytes[sizeof(g.geometry)];
      for (uint8_t& b : bytes) b = in.U8();
      for (size_t k = 3; k < sizeof(bytes); k += 4) bytes[k] &= 0x7f;  // its enum fields within MAX_ENUM (AnyEnum)
      std::memcpy(&g.geometry, bytes, sizeof(bytes));
      return;
    }
  }
  if (host_) PlaceHostInputs(in, info, g, range);
}

// Host inputs: each in the arena, with room for what the spec says the build reads given its range (so that any
// read past that is the layer's).
void BuildCall::PlaceHostInputs(ByteSource& in, const VkAccelerationStructureBuildGeometryInfoKHR& info,
                                VkAccelerationStructureGeometryKHR& g,
                                const VkAccelerationStructureBuildRangeInfoKHR& range) {
  HostArena& arena = device_.arena();
  const size_t count = range.primitiveCount;
  switch (g.geometryType) {
    case VK_GEOMETRY_TYPE_TRIANGLES_KHR: {
      VkAccelerationStructureGeometryTrianglesDataKHR& t = g.geometry.triangles;
      const size_t stride = std::max<size_t>(t.vertexStride, 16);
      const size_t vertices = range.primitiveOffset + stride * (range.firstVertex + t.maxVertex + 3 * count + 1) + 16;
      t.vertexData.hostAddress = in.OneIn(16) ? nullptr : arena.Place(in, vertices);
      t.indexData.hostAddress = in.OneIn(16) ? nullptr : arena.Place(in, range.primitiveOffset + 12 * count + 4);
      t.transformData.hostAddress = in.Bit() ? nullptr : arena.Place(in, range.transformOffset + 48);
      break;
    }
    case VK_GEOMETRY_TYPE_AABBS_KHR: {
      VkAccelerationStructureGeometryAabbsDataKHR& a = g.geometry.aabbs;
      const size_t stride = std::max<size_t>(a.stride, 24);
      a.data.hostAddress = in.OneIn(16) ? nullptr : arena.Place(in, range.primitiveOffset + stride * count + 24);
      break;
    }
    case VK_GEOMETRY_TYPE_INSTANCES_KHR: {
      VkAccelerationStructureGeometryInstancesDataKHR& d = g.geometry.instances;
      if (in.OneIn(16)) {
        d.data.hostAddress = nullptr;
        break;
      }
      if (d.arrayOfPointers == VK_TRUE) {  // each pointer null or at a whole instance in the arena
        std::vector<uint8_t>& array = pointer_arrays_.emplace_back(range.primitiveOffset + 8 * count);
        for (size_t k = 0; k < count; ++k) {
          const void* pointer = in.OneIn(8) ? nullptr : arena.Place(in, 160);
          std::memcpy(array.data() + range.primitiveOffset + k * sizeof(void*), &pointer, sizeof(pointer));
        }
        d.data.hostAddress = array.data();
        break;
      }
      // Motion instances are larger; the layer does not read them, but the room is theirs.
      const size_t record = (info.flags & VK_BUILD_ACCELERATION_STRUCTURE_MOTION_BIT_NV) ? 160 : 64;
      uint8_t* base = arena.Place(in, range.primitiveOffset + record * count);
      d.data.hostAddress = base;
      for (size_t k = 0; k < count; ++k) {  // references: structures of the device, destroyed, unknown, 0
        if (!in.Bit()) continue;
        const uint64_t reference = reinterpret_cast<uint64_t>(device_.Structure(in));
        std::memcpy(base + range.primitiveOffset + k * record +
                        offsetof(VkAccelerationStructureInstanceKHR, accelerationStructureReference),
                    &reference, sizeof(reference));
      }
      break;
    }
    default: break;
  }
}

const void* BuildCall::Chain(ByteSource& in) {
  if (!in.OneIn(4)) return nullptr;
  const void* next = nullptr;
  const uint32_t length = 1 + in.Below(3);
  for (uint32_t k = 0; k < length; ++k) {
    auto node = std::make_unique<ChainNode>();
    std::memset(node->bytes, 0, sizeof(node->bytes));  // known structures: null pointers, zero counts
    const bool known = in.Bit();
    const VkStructureType type = known ? KnownChainType(in) : in.AnyEnum<VkStructureType>();
    const VkBaseInStructure header{type, static_cast<const VkBaseInStructure*>(next)};
    if (!known) {  // a structure the layer cannot know: any bytes after its header
      const uint64_t word = in.U64();
      for (size_t b = sizeof(header); b + 8 <= sizeof(node->bytes); b += 8) std::memcpy(node->bytes + b, &word, 8);
    }
    std::memcpy(node->bytes, &header, sizeof(header));
    next = node->bytes;
    chain_nodes_.push_back(std::move(node));
  }
  return next;
}

VkDeviceOrHostAddressConstKHR BuildCall::Address(ByteSource& in) {
  VkDeviceOrHostAddressConstKHR address{};
  address.deviceAddress = device_.DeviceAddress(in);
  return address;
}

}  // namespace asval::fuzz
