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
#include "build_command.h"
#include "check_context.h"

namespace asval {

bool ValidateInputAlignment(const CheckContext& ctx, const BuildCommand& cmd);

}  // namespace asval
