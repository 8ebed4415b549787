#pragma once
// The instance references of a host build, read from the app's host memory: for vkBuildAccelerationStructuresKHR,
// VkAccelerationStructureInstanceKHR::accelerationStructureReference holds a VkAccelerationStructureKHR handle,
// and the instance data is readable when the command is called (unlike device builds, whose instances live on
// the device). Used by the host rules (pInfos-03779, 03724, 03777) and the aliasing rules (None-03407,
// dstAccelerationStructure-03706).
#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

#include "build_command.h"
#include "device_state.h"

namespace asval {

// Appends to `out` the non-zero references of the instances geometry j of pInfos[i] builds (host builds; instance
// geometries with a known count), then sorts and removes duplicates from all of `out`. False, leaving `out`
// alone, when the data cannot be read here: not a host build, not an instance geometry, no range, a null data
// pointer (pInfos-03778 says so), motion instances (a layout this reader does not walk), or, on a device without
// host commands, data outside the app's mappings (host_reads.h); instances whose pointer is null or outside them
// are passed over.
bool CollectInstanceReferences(const DeviceState& state, const BuildCommand& cmd, uint32_t i, uint32_t j,
                               std::vector<uint64_t>& out);

// Index of the first instance of geometry j of pInfos[i] whose reference is `reference` (for messages); the
// count when none is.
uint32_t FirstInstanceReferencing(const DeviceState& state, const BuildCommand& cmd, uint32_t i, uint32_t j,
                                  uint64_t reference);

}  // namespace asval
