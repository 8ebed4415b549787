#include "host_command_features.h"

#include <fmt/format.h>

#include <string>

namespace asval {

namespace {

[[gnu::cold, gnu::noinline]] bool ReportMissingHostCommands(const CheckContext& ctx, const char* function,
                                                            const char* vuid_suffix) {
  return ctx.reporter.Report(Severity::kError, fmt::format("VUID-{}-{}", function, vuid_suffix), Location(function),
                             {},
                             "was called, but the VkPhysicalDeviceAccelerationStructureFeaturesKHR::"
                             "accelerationStructureHostCommands feature was not enabled when the device was created.");
}

}  // namespace

bool ValidateHostCommandFeature(const CheckContext& ctx, const char* function, const char* vuid_suffix) {
  if (ctx.state.features.acceleration_structure_host_commands) return false;
  return ReportMissingHostCommands(ctx, function, vuid_suffix);
}

}  // namespace asval
