#pragma once
// The bytes a device build reads from its geometry inputs, and the rules that they lie in one bound buffer
// with BUILD_INPUT_READ_ONLY usage (family "addresses": pInfos-03804 / 03806 / 03808 / 03811 / 03813 and
// geometry-03673, see build_addresses.h), for geometry j of pInfos[i]: run by the addresses family's walk and by
// the geometry pass (geometry_pass.h), through a judge (rule_judge.h).
#include <cstdint>

#include "buffer_lookup.h"
#include "buffer_memo.h"
#include "build_command.h"
#include "check_context.h"
#include "geometry_facts.h"

namespace asval {

inline constexpr VkBufferUsageFlags kInputUsage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR;

// Which input a read is: names its field and rule in a message.
enum class InputKind : uint8_t { kVertices, kIndices, kTransform, kAabbs, kInstances, kInstancePointers };

// One range a geometry reads.
struct InputRead {
  InputKind kind;
  bool ranged;              // size comes from the build range (else: the first byte only)
  VkDeviceAddress address;
  VkDeviceSize size;        // bytes read from address on (at least 1)
};

// Bytes of one vertex of a format (never more than the real size: a range the layer computes must be a lower
// bound of what the build reads): the texel size for the acceleration-structure vertex formats the shared
// table decodes, else the format's alignment unit, at least 1.
inline VkDeviceSize VertexBytes(const VertexFormatInfo& facts) {
  if (facts.decodable) return facts.vertexBytes;
  return facts.componentBytes ? facts.componentBytes : 1;
}

// Calls visit(const InputRead&) for each range geometry f reads. With a range (direct builds): exactly the
// bytes the specification says the build consumes. Without (indirect builds, whose ranges live on the device):
// the first byte of each input.
template <typename Visit>
[[gnu::always_inline]] inline bool ForEachRead(const GeometryFacts& f, const VkAccelerationStructureBuildRangeInfoKHR* r,
                                               Visit&& visit) {
  constexpr VkDeviceSize kTransformBytes = sizeof(VkTransformMatrixKHR);               // 48
  constexpr VkDeviceSize kAabbBytes = sizeof(VkAabbPositionsKHR);                      // 24
  constexpr VkDeviceSize kInstanceBytes = sizeof(VkAccelerationStructureInstanceKHR);  // 64 (motion: more)
  const VkAccelerationStructureGeometryKHR& g = f.geometry;
  const VkDeviceSize count = r ? r->primitiveCount : 0;
  const VkDeviceSize offset = r ? r->primitiveOffset : 0;
  bool result = false;
  switch (g.geometryType) {
    case VK_GEOMETRY_TYPE_TRIANGLES_KHR: {
      const VkAccelerationStructureGeometryTrianglesDataKHR& t = g.geometry.triangles;
      InputRead vertices{InputKind::kVertices, false, t.vertexData.deviceAddress, 1};
      // f.index_size is 0 exactly for VK_INDEX_TYPE_NONE_KHR (IndexTypeSize), and already loaded.
      if (r && f.index_size == 0) {
        // primitiveCount x 3 vertices from primitiveOffset + vertexStride x firstVertex; the last one is read
        // for its format's size, not its stride.
        const VkDeviceSize last = SaturatingAdd(r->firstVertex, SaturatingMul(3, count) - 1);
        vertices.size =
            SaturatingAdd(offset, SaturatingAdd(SaturatingMul(t.vertexStride, last), VertexBytes(f.format)));
        vertices.ranged = true;
      }
      result |= visit(vertices);
      // Indexed vertices are fetched where the indices say; only the start is known without reading them.
      if (f.index_size > 0) {
        InputRead indices{InputKind::kIndices, r != nullptr, t.indexData.deviceAddress, 1};
        if (r) indices.size = SaturatingAdd(offset, SaturatingMul(SaturatingMul(3, count), f.index_size));
        result |= visit(indices);
      }
      if (t.transformData.deviceAddress != 0) {
        InputRead transform{InputKind::kTransform, r != nullptr, t.transformData.deviceAddress, 1};
        if (r) transform.size = SaturatingAdd(r->transformOffset, kTransformBytes);
        result |= visit(transform);
      }
      return result;
    }
    case VK_GEOMETRY_TYPE_AABBS_KHR: {
      const VkAccelerationStructureGeometryAabbsDataKHR& a = g.geometry.aabbs;
      InputRead aabbs{InputKind::kAabbs, r != nullptr, a.data.deviceAddress, 1};
      if (r) aabbs.size = SaturatingAdd(offset, SaturatingAdd(SaturatingMul(a.stride, count - 1), kAabbBytes));
      return visit(aabbs);
    }
    case VK_GEOMETRY_TYPE_INSTANCES_KHR: {
      const VkAccelerationStructureGeometryInstancesDataKHR& d = g.geometry.instances;
      const bool pointers = d.arrayOfPointers == VK_TRUE;
      InputRead instances{pointers ? InputKind::kInstancePointers : InputKind::kInstances, r != nullptr,
                          d.data.deviceAddress, 1};
      if (r) {
        instances.size = SaturatingAdd(offset, SaturatingMul(count, pointers ? sizeof(VkDeviceAddress) : kInstanceBytes));
      }
      return visit(instances);
    }
    default:
      return false;  // geometry types of extensions: not judged
  }
}

// The reporting half (cold): which rule the read breaks, or unknown state when a sparse buffer may hold it.
[[gnu::cold, gnu::noinline]] bool ReportInputRead(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i,
                                                  uint32_t j, const InputRead& read);

// The buffer that held the last read of a walk over an info's geometries (with kInputUsage): the geometries of a
// build mostly read one vertex buffer, so a read that lies inside it is held without asking the memo. Exact: the
// window is a copy of a memo entry that served kInputUsage, and every entry stays a right answer for the call (the
// memo was synced at its start); a read outside it asks the memo as before.
struct InputWindow {
  KnownBuffer held;  // size 0 (nothing yet) holds nothing
};

// The reads of geometry f (with its range, or null for an indirect build), each in one buffer of `memo`'s
// device with kInputUsage.
template <typename Judge>
[[gnu::always_inline]] inline bool InputReadRules(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j, const GeometryFacts& f,
                    const VkAccelerationStructureBuildRangeInfoKHR* range, BufferMemo& memo, InputWindow& window,
                    const Judge& judge) {
  return ForEachRead(f, range, [&](const InputRead& read) {
    if (window.held.Holds(read.address, read.size == 0 ? 1 : read.size)) return false;
    if (const KnownBuffer* held = memo.Held(ctx.state, read.address, read.size, kInputUsage)) {
      window.held.base = held->base;
      window.held.size = held->size;
      return false;
    }
    return judge.Broken([&] { return ReportInputRead(ctx, cmd, i, j, read); });
  });
}

}  // namespace asval
