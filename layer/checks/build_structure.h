#pragma once
// Structure rules of the build commands' inputs (family "structure"), for all three commands:
// VkAccelerationStructureBuildGeometryInfoKHR type-03654, pGeometries-03788, type-03789..03795, flags-03796,
// flags-07334; the geometry data rules of VkAccelerationStructureGeometryTrianglesDataKHR (vertexStride-03735,
// vertexStride-03819, vertexFormat-03797, indexType-03798) and VkAccelerationStructureGeometryAabbsDataKHR
// (stride-03545, stride-03820). The range rules (VkAccelerationStructureBuildRangeInfoKHR) are in build_ranges.h.
// Only bits and values these headers name are judged: flag bits and geometry types of newer extensions are
// left alone.
#include "build_command.h"
#include "check_context.h"

namespace asval {

bool ValidateBuildStructure(const CheckContext& ctx, const BuildCommand& cmd);

}  // namespace asval
