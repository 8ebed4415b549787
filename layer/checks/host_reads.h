#pragma once
// Whether the layer may read a host build's input bytes now. With accelerationStructureHostCommands the app promises
// host pointers, and the layer reads what the driver is about to read. Without it vkBuildAccelerationStructuresKHR is
// invalid (03581) and its "host addresses" may be anything, device addresses above all (an app that meant a device
// build): then only bytes inside the app's live vkMapMemory mappings are read, which cannot fault. On a CPU device
// such as lavapipe a mapped buffer's device address is its host pointer, so those rules still run there.
#include <cstdint>

#include "device_state.h"

namespace asval {

inline bool HostBytesReadable(const DeviceState& state, const void* pointer, uint64_t bytes) {
  if (state.features.acceleration_structure_host_commands) return true;
  const auto begin = reinterpret_cast<uintptr_t>(pointer);
  const uintptr_t end = state.host_mappings.ContiguousEnd(begin);
  return end != 0 && bytes <= end - begin;
}

}  // namespace asval
