#pragma once
// The feature the host copy and property commands need (family "features"), as vkBuildAccelerationStructuresKHR
// needs it (build_features.h):
//   vkCopyAccelerationStructureKHR-accelerationStructureHostCommands-03582
//   vkCopyMemoryToAccelerationStructureKHR-accelerationStructureHostCommands-03583
//   vkCopyAccelerationStructureToMemoryKHR-accelerationStructureHostCommands-03584
//   vkWriteAccelerationStructuresPropertiesKHR-accelerationStructureHostCommands-03585
#include "check_context.h"

namespace asval {

// function: one of the four commands above; vuid_suffix: its "accelerationStructureHostCommands-0358x".
bool ValidateHostCommandFeature(const CheckContext& ctx, const char* function, const char* vuid_suffix);

}  // namespace asval
