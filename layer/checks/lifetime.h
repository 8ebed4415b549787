#pragma once
// Family "lifetime" (issue 29): a structure, buffer or memory destroyed or freed while a pending submission's
// acceleration-structure command uses it (vkDestroyAccelerationStructureKHR-accelerationStructure-02442,
// vkDestroyBuffer-buffer-00922, vkFreeMemory-memory-00677). A command uses a structure it builds, updates, copies,
// serializes or queries (its handle), the buffer and memory under that structure, and every buffer and memory
// holding an address it reads or writes (scratch, geometry inputs, instances, serialized bytes). An address is not
// an identity: a buffer is the one a command uses only when it was bound before the submission and no other live
// buffer bound before it holds the address. Whether the command completed is the device's answer (in_flight.h).
//
// These run before the destroy goes down; they only report (the in-flight set retires what it finds complete).
// True when the app asked that the call not be made.
#include <vulkan/vulkan.h>

#include "check_context.h"
#include "in_flight.h"

namespace asval {

bool CheckDestroyStructureInUse(const CheckContext& ctx, InFlight& in_flight, VkAccelerationStructureKHR structure);
bool CheckDestroyBufferInUse(const CheckContext& ctx, InFlight& in_flight, VkBuffer buffer);
bool CheckFreeMemoryInUse(const CheckContext& ctx, InFlight& in_flight, VkDeviceMemory memory);

inline constexpr const char kLifetimeSummaryId[] = "ASVAL-Lifetime-Summary";
// vkDestroyDevice: what the family judged and could not judge (info; in the JSON report whenever something was
// skipped).
void ReportLifetimeSummary(const DeviceState& state, Reporter& reporter, VkDevice device);

}  // namespace asval
