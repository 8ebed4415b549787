#pragma once
// One pass over a build command for the two families that place its bytes in memory: "addresses"
// (build_addresses.h, build_sizes.h) and "aliasing" (build_aliasing.h). Both need, per info, the driver's sizes,
// where the destination lives and which buffer holds the scratch; looking each up once per info (and each
// buffer once per call, BufferMemo) instead of once per family halves the cost of a many-info call. Either
// family can still be switched off alone.
#include <optional>

#include "buffer_memo.h"
#include "build_command.h"
#include "build_size_cache.h"
#include "check_context.h"

namespace asval {

// What both families know about pInfos[i] before judging it.
struct InfoResolution {
  std::optional<BuildSizes> sizes;  // nullopt: unknown (counted)
  // The destination's record and its buffer; structure null when the handle is not a live structure.
  std::shared_ptr<const AccelerationStructureState> dst;
  KnownBuffer dst_buffer;
  bool dst_buffer_known = false;
  // Bytes of scratch this build needs (build or update size), and, for device builds, the buffer holding
  // them all with STORAGE_BUFFER usage when there is one.
  VkDeviceSize scratch_bytes = 0;
  bool scratch_in_storage = false;
  KnownBuffer scratch_buffer;
};

// The families' entry in the build-family table: runs whichever of the two the settings enable.
inline constexpr LayerSettingFlagBits kCheckAddressesOrAliasing =
    static_cast<LayerSettingFlagBits>(kCheckAddresses | kCheckAliasing);
bool ValidateBuildMemory(const CheckContext& ctx, const BuildCommand& cmd);

}  // namespace asval
