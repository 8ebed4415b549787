#include "build_addresses.h"

#include <array>
#include <cstdint>

#include "asval/vertex_formats.h"
#include "buffer_lookup.h"
#include "buffer_memo.h"
#include "build_report.h"
#include "build_sizes.h"
#include "vertex_format_alignment.h"
#include "vk_enum_string.h"

namespace asval {

namespace {

constexpr VkBufferUsageFlags kInputUsage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR;
constexpr VkDeviceSize kTransformBytes = sizeof(VkTransformMatrixKHR);     // 48
constexpr VkDeviceSize kAabbBytes = sizeof(VkAabbPositionsKHR);            // 24
constexpr VkDeviceSize kInstanceBytes = sizeof(VkAccelerationStructureInstanceKHR);  // 64 (motion instances: more)

// Bytes of one vertex of `format` (never more than the real size: a range the layer computes must be a lower
// bound of what the build reads): the texel size for the acceleration-structure vertex formats the shared
// table decodes, else the format's alignment unit, at least 1. One table index on the hot path.
VkDeviceSize VertexBytes(VkFormat format) {
  const VertexFormatInfo& facts = VertexFormatFacts(format);
  if (facts.decodable) return facts.vertexBytes;
  return facts.componentBytes ? facts.componentBytes : 1;
}

// One range a geometry reads, and the rule that makes its start a valid device address. No default member
// initializers: ReadsOfGeometry assigns every member of each read it returns, and the clean path should not
// pay for clearing three of them per geometry.
struct InputRead {
  const char* data_member;  // "triangles", "aabbs", "instances"
  const char* field;        // "vertexData", "indexData", "transformData", "data"
  const char* valid_vuid;   // "pInfos-03804", ...
  const char* how;          // how the size was found, for the message
  VkDeviceAddress address;
  VkDeviceSize size;        // bytes read from address on (at least 1)
};

// The ranges geometry g reads. With a range (direct builds): exactly the bytes the specification says the
// build consumes. Without (indirect builds, whose ranges live on the device): the first byte of each input.
int ReadsOfGeometry(const VkAccelerationStructureGeometryKHR& g, const VkAccelerationStructureBuildRangeInfoKHR* r,
                    InputRead out[3]) {
  int n = 0;
  const VkDeviceSize count = r ? r->primitiveCount : 0;
  const VkDeviceSize offset = r ? r->primitiveOffset : 0;
  switch (g.geometryType) {
    case VK_GEOMETRY_TYPE_TRIANGLES_KHR: {
      const VkAccelerationStructureGeometryTrianglesDataKHR& t = g.geometry.triangles;
      const int index_bytes = IndexTypeSize(t.indexType);
      InputRead& vertices = out[n++];
      vertices = {"triangles", "vertexData", "pInfos-03804", "its first byte", t.vertexData.deviceAddress, 1};
      if (r && t.indexType == VK_INDEX_TYPE_NONE_KHR) {
        // primitiveCount x 3 vertices from primitiveOffset + vertexStride x firstVertex; the last one is read
        // for its format's size, not its stride.
        const VkDeviceSize last = SaturatingAdd(r->firstVertex, SaturatingMul(3, count) - 1);
        vertices.size = SaturatingAdd(offset, SaturatingAdd(SaturatingMul(t.vertexStride, last), VertexBytes(t.vertexFormat)));
        vertices.how = "primitiveOffset + vertexStride x (firstVertex + 3 x primitiveCount - 1) + the vertex size";
      }
      // Indexed vertices are fetched where the indices say; only the start is known without reading them.
      if (t.indexType != VK_INDEX_TYPE_NONE_KHR && index_bytes > 0) {
        InputRead& indices = out[n++];
        indices = {"triangles", "indexData", "pInfos-03806", "its first byte", t.indexData.deviceAddress, 1};
        if (r) {
          indices.size = SaturatingAdd(offset, SaturatingMul(SaturatingMul(3, count), index_bytes));
          indices.how = "primitiveOffset + 3 x primitiveCount indices";
        }
      }
      if (t.transformData.deviceAddress != 0) {
        InputRead& transform = out[n++];
        transform = {"triangles", "transformData", "pInfos-03808", "its first byte", t.transformData.deviceAddress, 1};
        if (r) {
          transform.size = SaturatingAdd(r->transformOffset, kTransformBytes);
          transform.how = "transformOffset + one VkTransformMatrixKHR";
        }
      }
      break;
    }
    case VK_GEOMETRY_TYPE_AABBS_KHR: {
      const VkAccelerationStructureGeometryAabbsDataKHR& a = g.geometry.aabbs;
      InputRead& aabbs = out[n++];
      aabbs = {"aabbs", "data", "pInfos-03811", "its first byte", a.data.deviceAddress, 1};
      if (r) {
        aabbs.size = SaturatingAdd(offset, SaturatingAdd(SaturatingMul(a.stride, count - 1), kAabbBytes));
        aabbs.how = "primitiveOffset + stride x (primitiveCount - 1) + one VkAabbPositionsKHR";
      }
      break;
    }
    case VK_GEOMETRY_TYPE_INSTANCES_KHR: {
      const VkAccelerationStructureGeometryInstancesDataKHR& d = g.geometry.instances;
      InputRead& instances = out[n++];
      instances = {"instances", "data", "pInfos-03813", "its first byte", d.data.deviceAddress, 1};
      if (r) {
        const bool pointers = d.arrayOfPointers == VK_TRUE;
        instances.size = SaturatingAdd(offset, SaturatingMul(count, pointers ? sizeof(VkDeviceAddress) : kInstanceBytes));
        instances.how = pointers ? "primitiveOffset + primitiveCount device addresses"
                                 : "primitiveOffset + primitiveCount VkAccelerationStructureInstanceKHR";
      }
      break;
    }
    default:
      break;  // geometry types of extensions: not judged
  }
  return n;
}

[[gnu::cold, gnu::noinline]] bool ReportRead(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j,
                                             const InputRead& read) {
  const DeviceState& state = ctx.state;
  if (SparseAddressBuffersExist(state)) {
    CountUnknownState(ctx);  // a sparse buffer the layer cannot see may hold these bytes
    return false;
  }
  const auto location = [&](std::string&) {
    return GeometryLocation(cmd, i, j).Field("geometry").Field(read.data_member).Field(read.field).Field("deviceAddress");
  };
  bool skip = false;
  if (read.size == 1 && !FindBufferHolding(state, read.address, 1, 0)) {
    skip |= ReportBuild(ctx, cmd, i, read.valid_vuid, location, "(0x{:x}) is not a valid VkDeviceAddress: {}.",
                        read.address, DescribeBuffersAt(state, read.address));
  } else if (!FindBufferHolding(state, read.address, read.size, 0)) {
    skip |= ReportBuild(ctx, cmd, i, read.valid_vuid, location,
                        "(0x{:x}) is not a valid VkDeviceAddress for the {} bytes this build reads from it "
                        "[0x{:x}, 0x{:x}) ({}): no single buffer holds them; {}.",
                        read.address, read.size, read.address, SaturatingAdd(read.address, read.size), read.how,
                        DescribeBuffersAt(state, read.address));
  }
  if (FindBufferHolding(state, read.address, 1, 0) && !FindBufferHolding(state, read.address, 1, kInputUsage)) {
    skip |= ReportBuild(ctx, cmd, i, "geometry-03673", location,
                        "(0x{:x}) comes from a buffer created without "
                        "VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR: {}.",
                        read.address, DescribeBuffersAt(state, read.address));
  }
  return skip;
}

bool ValidateGeometryInputs(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, BufferMemo& memo) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
  bool skip = false;
  for (uint32_t j = 0; j < info.geometryCount; ++j) {
    const VkAccelerationStructureGeometryKHR* g = GeometryAt(info, j);
    if (!g) return skip;
    const VkAccelerationStructureBuildRangeInfoKHR* range = nullptr;
    if (cmd.is_indirect()) {
      // A geometry whose maximum is 0 builds nothing and reads nothing.
      if (!cmd.max_primitive_counts || !cmd.max_primitive_counts[i] || cmd.max_primitive_counts[i][j] == 0) continue;
    } else {
      if (!cmd.ranges || !cmd.ranges[i]) return skip;
      range = &cmd.ranges[i][j];
      if (range->primitiveCount == 0) continue;  // reads nothing
    }
    InputRead reads[3];
    const int n = ReadsOfGeometry(*g, range, reads);
    for (int k = 0; k < n; ++k) {
      if (!memo.Held(ctx.state, reads[k].address, reads[k].size, kInputUsage)) {
        skip |= ReportRead(ctx, cmd, i, j, reads[k]);
      }
    }
  }
  return skip;
}

[[gnu::cold, gnu::noinline]] bool ReportScratch(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i,
                                                VkDeviceSize needed) {
  const DeviceState& state = ctx.state;
  if (SparseAddressBuffersExist(state)) {
    CountUnknownState(ctx);
    return false;
  }
  const VkDeviceAddress address = cmd.infos[i].scratchData.deviceAddress;
  const bool update = cmd.infos[i].mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
  const char* size_name = update ? "updateScratchSize" : "buildScratchSize";
  const char* address_rule = cmd.is_indirect() ? (update ? "pInfos-12260" : "pInfos-12261") : "pInfos-03802";
  const char* usage_rule = cmd.is_indirect() ? (update ? "pInfos-12260" : "pInfos-12261") : "pInfos-03674";
  const char* range_rule =
      cmd.is_indirect() ? (update ? "pInfos-12259" : "pInfos-12258") : (update ? "pInfos-03672" : "pInfos-03671");
  const auto location = [&](std::string&) {
    return InfoLocation(cmd, i).Field("scratchData").Field("deviceAddress");
  };
  if (!FindBufferHolding(state, address, 1, 0)) {
    return ReportBuild(ctx, cmd, i, address_rule, location,
                       "(0x{:x}) is not a valid VkDeviceAddress ({}), and this {} needs {} bytes of scratch ({}).",
                       address, DescribeBuffersAt(state, address), update ? "update" : "build", needed, size_name);
  }
  bool skip = false;
  if (!FindBufferHolding(state, address, 1, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT)) {
    skip |= ReportBuild(ctx, cmd, i, usage_rule, location,
                        "(0x{:x}) comes from a buffer created without VK_BUFFER_USAGE_STORAGE_BUFFER_BIT: {}.", address,
                        DescribeBuffersAt(state, address));
  }
  if (!FindBufferHolding(state, address, needed, 0)) {
    skip |= ReportBuild(ctx, cmd, i, range_rule, location,
                        "(0x{:x}): the {} bytes of scratch this {} needs ({} reported by "
                        "vkGetAccelerationStructureBuildSizesKHR for this geometry and these counts), "
                        "[0x{:x}, 0x{:x}), do not lie in one buffer: {}.",
                        address, needed, update ? "update" : "build", size_name, address,
                        SaturatingAdd(address, needed), DescribeBuffersAt(state, address));
  }
  return skip;
}

bool ValidateScratch(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, const ResolvedInfo& r) {
  // No size (counted by ValidateBuildMemory), or a zero size: no scratch is read or written.
  if (r.scratch_bytes == 0 || r.scratch_in_storage) return false;
  return ReportScratch(ctx, cmd, i, r.scratch_bytes);
}

[[gnu::cold, gnu::noinline]] bool ReportIndirectRanges(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i,
                                                       VkDeviceSize bytes) {
  const DeviceState& state = ctx.state;
  if (SparseAddressBuffersExist(state)) {
    CountUnknownState(ctx);
    return false;
  }
  const VkDeviceAddress address = cmd.indirect_addresses[i];
  const auto location = [&](std::string&) { return cmd.Root().Field("pIndirectDeviceAddresses", i); };
  bool skip = false;
  if (!FindBufferHolding(state, address, bytes, 0)) {
    skip |= ReportBuild(ctx, cmd, i, "pIndirectDeviceAddresses-03646", location,
                        "(0x{:x}): pInfos[{}].geometryCount ({}) x pIndirectStrides[{}] ({}) = {} bytes of build "
                        "ranges, [0x{:x}, 0x{:x}), do not lie in one buffer: {}.",
                        address, i, cmd.infos[i].geometryCount, i, cmd.indirect_strides[i], bytes, address,
                        SaturatingAdd(address, bytes), DescribeBuffersAt(state, address));
  }
  if (FindBufferHolding(state, address, 1, 0) &&
      !FindBufferHolding(state, address, 1, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT)) {
    skip |= ReportBuild(ctx, cmd, i, "pIndirectDeviceAddresses-03647", location,
                        "(0x{:x}) comes from a buffer created without VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT: {}.", address,
                        DescribeBuffersAt(state, address));
  }
  return skip;
}

bool ValidateIndirectRanges(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, BufferMemo& memo) {
  if (!cmd.indirect_addresses || !cmd.indirect_strides) return false;
  const VkDeviceSize bytes = SaturatingMul(cmd.infos[i].geometryCount, cmd.indirect_strides[i]);
  if (bytes == 0) return false;  // no range is read
  if (memo.Held(ctx.state, cmd.indirect_addresses[i], bytes, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT)) {
    return false;
  }
  return ReportIndirectRanges(ctx, cmd, i, bytes);
}

}  // namespace

bool ValidateInfoAddresses(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, const ResolvedInfo& r,
                           BufferMemo& memo) {
  bool skip = ValidateInfoSizes(ctx, cmd, i, r);
  if (cmd.is_host()) return skip;  // host addresses: build_host.h
  skip |= ValidateScratch(ctx, cmd, i, r);
  skip |= ValidateGeometryInputs(ctx, cmd, i, memo);
  if (cmd.is_indirect()) skip |= ValidateIndirectRanges(ctx, cmd, i, memo);
  return skip;
}

}  // namespace asval
