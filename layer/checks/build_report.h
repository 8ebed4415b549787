#pragma once
// The reporting half shared by the build-command rule families: object lists, locations of infos and
// geometries, and one cold, out-of-line function template that formats a finding. A check's clean path
// only compares; everything here runs when something is reported.
#include <fmt/format.h>

#include <string>
#include <string_view>
#include <utility>

#include "build_command.h"
#include "check_context.h"

namespace asval {

// A handle as messages write it: "0x1a2b".
inline std::string Hex(const void* handle) { return fmt::format("0x{:x}", reinterpret_cast<uintptr_t>(handle)); }

// For findings about the command as a whole rather than one element of pInfos.
inline constexpr uint32_t kNoInfo = UINT32_MAX;

// "pInfos[i]".
inline Location InfoLocation(const BuildCommand& cmd, uint32_t i) { return cmd.Root().Field("pInfos", i); }

// "pInfos[i].pGeometries[j]" or "pInfos[i].ppGeometries[j]", whichever array the app used.
inline Location GeometryLocation(const BuildCommand& cmd, uint32_t i, uint32_t j) {
  return InfoLocation(cmd, i).Field(cmd.infos[i].pGeometries ? "pGeometries" : "ppGeometries", j);
}

// vuid is either a whole VUID ("VUID-VkAccelerationStructureGeometryAabbsDataKHR-stride-03545") or the part
// after the command's name ("pInfos-03711"), which becomes "VUID-<cmd.function>-pInfos-03711". The objects
// are the command buffer (device builds) or the device (host builds), and pInfos[info_index]'s destination.
bool ReportBuildFinding(const CheckContext& ctx, const BuildCommand& cmd, uint32_t info_index, std::string_view vuid,
                        const Location& loc, std::string_view message);

// make_location(std::string& storage) returns the finding's Location; it may keep a path element that is
// built at report time (ppBuildRangeInfos[i][j]) in storage, which outlives the report.
template <typename MakeLocation, typename... Args>
[[gnu::cold, gnu::noinline]] bool ReportBuild(const CheckContext& ctx, const BuildCommand& cmd, uint32_t info_index,
                                              std::string_view vuid, MakeLocation&& make_location,
                                              fmt::format_string<Args...> format, Args&&... args) {
  std::string storage;
  const Location loc = make_location(storage);
  return ReportBuildFinding(ctx, cmd, info_index, vuid, loc, fmt::format(format, std::forward<Args>(args)...));
}

// Whether the per-geometry rules may walk pInfos[i]'s geometries: it names an array, and (bottom level) no
// more geometries than maxGeometryCount. Beyond that limit the build is invalid as a whole (type-03793) and
// walking an absurd count would cost the layer what the driver never spends.
inline bool GeometriesWalkable(const CheckContext& ctx, const VkAccelerationStructureBuildGeometryInfoKHR& info) {
  if (!info.pGeometries && !info.ppGeometries) return false;
  return GeometryCountWithinLimit(info, ctx.state.properties.acceleration_structure.maxGeometryCount);
}

// Counts a check that could not run because the state it needs is unknown (never guessed).
inline void CountUnknownState(const CheckContext& ctx) {
  ctx.state.checks_skipped_unknown_state.fetch_add(1, std::memory_order_relaxed);
}

}  // namespace asval
