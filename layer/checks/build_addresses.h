#pragma once
// Device addresses of the build commands (family "addresses"): every range a device build reads or writes
// lies in one bound buffer of this device, created with the usage the rule asks for.
//   pInfos-03804 / 03806 / 03808 / 03811 / 03813   vertex, index, transform, AABB and instance data are valid
//       device addresses: the bytes the build reads (from ppBuildRangeInfos: primitiveOffset, firstVertex,
//       counts, strides; indirect builds: the first byte only, their ranges live on the device) lie in one
//       buffer
//   geometry-03673                                  ... created with ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY
//   direct builds: pInfos-03802 (scratch is a valid address), 03674 (STORAGE_BUFFER usage), 03671 / 03672
//       (the build or update scratch size from the driver fits in one buffer)
//   indirect builds: pInfos-12258 / 12259 (range) and 12260 / 12261 (STORAGE_BUFFER), which apply when that
//       size is not 0; the direct command's rules are read the same way (a zero-size scratch reads nothing)
//   pIndirectDeviceAddresses-03646 / 03647          the build ranges lie in one buffer with INDIRECT_BUFFER usage
// Host builds use host addresses: their rules are in build_host.h. Sizes and limits: build_sizes.h.
#include "buffer_memo.h"
#include "build_sizes.h"
#include "build_command.h"
#include "resolved_build.h"
#include "check_context.h"

namespace asval {

// The rules above, plus those of build_sizes.h, for pInfos[i] (called by ValidateBuildMemory).
bool ValidateInfoAddresses(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, const ResolvedInfo& r,
                           BufferMemo& memo);

// Whether ValidateInfoAddresses certainly has nothing to report or count for pInfos[i] of a device build: the sizes
// are clean (InfoSizesClean), the scratch is empty or lies in a STORAGE_BUFFER buffer, the geometry pass found no
// input read to judge, and the build is direct (no indirect ranges). Compares only: the caller tests it before any
// call.
inline bool InfoAddressesClean(const BuildCommand& cmd, const ResolvedInfo& r) {
  return InfoSizesClean(r) && !cmd.is_host() && (r.scratch_bytes == 0 || r.scratch_in_storage) &&
         !(r.walks & kWalkInputReads) && !cmd.is_indirect();
}

}  // namespace asval
