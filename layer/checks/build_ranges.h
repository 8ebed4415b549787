#pragma once
// Rules of VkAccelerationStructureBuildRangeInfoKHR (family "structure") for the direct and host builds,
// whose ranges the app passes on the host (an indirect build's ranges live in device memory):
//   primitiveOffset-03656  indexed triangles: a multiple of the index size
//   primitiveOffset-03657  non-indexed triangles: a multiple of the vertex format's component (packed) size
//   transformOffset-03658  triangles: a multiple of 16
//   primitiveOffset-03659  AABBs: a multiple of 8
//   primitiveOffset-03660  instances: a multiple of 16
//   vertexData-10418       non-indexed triangles: primitiveCount * 3 vertices fit in maxVertex + 1
//   None-10775             non-indexed triangles: maxVertex >= firstVertex + primitiveCount * 3 - 1
//   maxVertex-10774        indexed triangles, host builds only (the indices are host memory the layer can read
//                          now): maxVertex >= firstVertex + the largest index used
#include "build_command.h"
#include "check_context.h"

namespace asval {

bool ValidateBuildRanges(const CheckContext& ctx, const BuildCommand& cmd);

}  // namespace asval
