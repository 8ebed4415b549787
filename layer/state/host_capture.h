#pragma once
// Host builds' inputs, copied when vkBuildAccelerationStructuresKHR is called (the bytes are host memory, there to
// read): the same plan as a device build's execution-time capture (capture_plan.h), into layer-owned heap memory
// instead of device slabs, so that a host build's activity is recorded in its destination's history and a host
// update is judged on its own inputs (pInfos-03663, 03664, 03768) like a device one.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "capture_log.h"

namespace asval {

struct HostCapture {
  std::shared_ptr<CaptureLog> log;  // null: nothing captured
  std::vector<uint32_t> captured;   // per info: its index in log->infos plus one, or 0
  const uint32_t* captured_or_null() const { return log ? captured.data() : nullptr; }
};

// Copies what the infos with ALLOW_UPDATE, and the updates, read (each info whole or not at all; at most
// budget_bytes in all). Counted in `counters`.
HostCapture CaptureHostBuildInputs(uint32_t info_count, const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                                   const VkAccelerationStructureBuildRangeInfoKHR* const* ranges,
                                   VkDeviceSize budget_bytes, CaptureCounters& counters);

}  // namespace asval
