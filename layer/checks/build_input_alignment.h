#pragma once
// Alignment of the device addresses a device build reads (family "alignment"; host builds read host
// pointers, which no alignment rule covers):
//   pInfos-03711  triangles: vertexData to the vertex format's component size (the packed size for a packed
//                 format)
//   pInfos-03712  indexed triangles: indexData to the index size
//   pInfos-03810  triangles: a non-zero transformData to 16
//   pInfos-03714  AABBs: data to 8
//   pInfos-03715  instances, arrayOfPointers VK_FALSE: data to 16
//   pInfos-03716  instances, arrayOfPointers VK_TRUE: data to 8
//   pIndirectDeviceAddresses-03648, pIndirectStrides-03787  indirect builds: each a multiple of 4
#include <cstdint>

#include "build_command.h"
#include "check_context.h"
#include "geometry_facts.h"
#include "resolved_build.h"

namespace asval {

bool ValidateInputAlignment(const CheckContext& ctx, const BuildCommand& cmd, const ResolvedBuild& resolved);

// The input addresses these rules cover. The clean path passes only this and two numbers to the reporting
// half, so it materialises no message pieces (field names, lambdas) in its own frame.
enum class AlignedInput { kVertexData, kIndexData, kTransformData, kAabbData, kInstances, kInstancePointers };

[[gnu::cold, gnu::noinline]] bool ReportMisalignedInput(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i,
                                                        uint32_t j, AlignedInput input, VkDeviceAddress address,
                                                        uint32_t alignment);

// The rules above (but the indirect arrays') for geometry j of pInfos[i], through a judge (rule_judge.h).
template <typename Judge>
[[gnu::always_inline]] inline bool InputAlignmentRules(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j,
                         const GeometryFacts& f, const Judge& judge) {
  const auto broken = [&](AlignedInput input, VkDeviceAddress address, uint32_t alignment) {
    return judge.Broken([&] { return ReportMisalignedInput(ctx, cmd, i, j, input, address, alignment); });
  };
  switch (f.geometry.geometryType) {
    case VK_GEOMETRY_TYPE_TRIANGLES_KHR: {
      const VkAccelerationStructureGeometryTrianglesDataKHR& tri = f.geometry.geometry.triangles;
      bool skip = false;
      const uint32_t alignment = f.format.componentBytes;
      if (alignment == 0) {
        skip |= judge.Unknown();
      } else if ((tri.vertexData.deviceAddress & (alignment - 1)) != 0) {
        skip |= broken(AlignedInput::kVertexData, tri.vertexData.deviceAddress, alignment);
      }
      const int index_size = f.index_size;
      if (index_size > 1 && (tri.indexData.deviceAddress & (index_size - 1)) != 0) {
        skip |= broken(AlignedInput::kIndexData, tri.indexData.deviceAddress, static_cast<uint32_t>(index_size));
      }
      if ((tri.transformData.deviceAddress & 15) != 0) {
        skip |= broken(AlignedInput::kTransformData, tri.transformData.deviceAddress, 16);
      }
      return skip;
    }
    case VK_GEOMETRY_TYPE_AABBS_KHR: {
      const VkDeviceAddress address = f.geometry.geometry.aabbs.data.deviceAddress;
      if ((address & 7) == 0) return false;
      return broken(AlignedInput::kAabbData, address, 8);
    }
    case VK_GEOMETRY_TYPE_INSTANCES_KHR: {
      const VkAccelerationStructureGeometryInstancesDataKHR& instances = f.geometry.geometry.instances;
      const VkDeviceAddress address = instances.data.deviceAddress;
      if (instances.arrayOfPointers) {
        if ((address & 7) == 0) return false;
        return broken(AlignedInput::kInstancePointers, address, 8);
      }
      if ((address & 15) == 0) return false;
      return broken(AlignedInput::kInstances, address, 16);
    }
    default:
      return false;
  }
}

}  // namespace asval
