#pragma once
// Per-geometry rules of VkAccelerationStructureGeometryTrianglesDataKHR and
// VkAccelerationStructureGeometryAabbsDataKHR (family "structure"); called by ValidateBuildStructure for
// geometry j of pInfos[i].
#include "build_command.h"
#include "check_context.h"

namespace asval {

bool ValidateGeometryData(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j,
                          const VkAccelerationStructureGeometryKHR& geometry);

}  // namespace asval
