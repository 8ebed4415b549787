#include "build_addresses.h"

#include <array>
#include <cstdint>

#include "buffer_lookup.h"
#include "buffer_memo.h"
#include "build_input_reads.h"
#include "build_report.h"
#include "build_sizes.h"
#include "rule_judge.h"

namespace asval {

namespace {

// Out of line: walked only for infos the geometry pass flagged.
[[gnu::noinline]] bool ValidateGeometryInputs(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i,
                                              BufferMemo& memo) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
  if (!GeometriesWalkable(ctx, info)) return false;  // past maxGeometryCount: type-03793 says it, nothing is walked
  ReportingJudge judge{ctx};
  GeometryFactsReader facts(ctx.state);
  InputWindow window;
  bool skip = false;
  for (uint32_t j = 0; j < info.geometryCount; ++j) {
    const VkAccelerationStructureGeometryKHR* g = GeometryAt(info, j);
    if (!g) return skip;
    const VkAccelerationStructureBuildRangeInfoKHR* range = nullptr;
    if (cmd.is_indirect()) {
      // A geometry whose maximum is 0 builds nothing and reads nothing.
      if (!cmd.max_primitive_counts || !cmd.max_primitive_counts[i] || cmd.max_primitive_counts[i][j] == 0) continue;
    } else {
      if (!cmd.ranges || !cmd.ranges[i]) return skip;
      range = &cmd.ranges[i][j];
      if (range->primitiveCount == 0) continue;  // reads nothing
    }
    skip |= InputReadRules(ctx, cmd, i, j, facts.Read(*g), range, memo, window, judge);
  }
  return skip;
}

[[gnu::cold, gnu::noinline]] bool ReportScratch(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i,
                                                VkDeviceSize needed) {
  const DeviceState& state = ctx.state;
  if (SparseAddressBuffersExist(state)) {
    CountUnknownState(ctx);
    return false;
  }
  const VkDeviceAddress address = cmd.infos[i].scratchData.deviceAddress;
  const bool update = cmd.infos[i].mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
  const char* size_name = update ? "updateScratchSize" : "buildScratchSize";
  const char* address_rule = cmd.is_indirect() ? (update ? "pInfos-12260" : "pInfos-12261") : "pInfos-03802";
  const char* usage_rule = cmd.is_indirect() ? (update ? "pInfos-12260" : "pInfos-12261") : "pInfos-03674";
  const char* range_rule =
      cmd.is_indirect() ? (update ? "pInfos-12259" : "pInfos-12258") : (update ? "pInfos-03672" : "pInfos-03671");
  const auto location = [&](std::string&) {
    return InfoLocation(cmd, i).Field("scratchData").Field("deviceAddress");
  };
  if (!FindBufferHolding(state, address, 1, 0)) {
    return ReportBuild(ctx, cmd, i, address_rule, location,
                       "(0x{:x}) is not a valid VkDeviceAddress ({}), and this {} needs {} bytes of scratch ({}).",
                       address, DescribeBuffersAt(state, address), update ? "update" : "build", needed, size_name);
  }
  bool skip = false;
  if (!FindBufferHolding(state, address, 1, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT)) {
    skip |= ReportBuild(ctx, cmd, i, usage_rule, location,
                        "(0x{:x}) comes from a buffer created without VK_BUFFER_USAGE_STORAGE_BUFFER_BIT: {}.", address,
                        DescribeBuffersAt(state, address));
  }
  if (!FindBufferHolding(state, address, needed, 0)) {
    skip |= ReportBuild(ctx, cmd, i, range_rule, location,
                        "(0x{:x}): the {} bytes of scratch this {} needs ({} reported by "
                        "vkGetAccelerationStructureBuildSizesKHR for this geometry and these counts), "
                        "[0x{:x}, 0x{:x}), do not lie in one buffer: {}.",
                        address, needed, update ? "update" : "build", size_name, address,
                        SaturatingAdd(address, needed), DescribeBuffersAt(state, address));
  }
  return skip;
}

bool ValidateScratch(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, const ResolvedInfo& r) {
  // No size (counted by ValidateBuildMemory), or a zero size: no scratch is read or written.
  if (r.scratch_bytes == 0 || r.scratch_in_storage) return false;
  return ReportScratch(ctx, cmd, i, r.scratch_bytes);
}

[[gnu::cold, gnu::noinline]] bool ReportIndirectRanges(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i,
                                                       VkDeviceSize bytes) {
  const DeviceState& state = ctx.state;
  if (SparseAddressBuffersExist(state)) {
    CountUnknownState(ctx);
    return false;
  }
  const VkDeviceAddress address = cmd.indirect_addresses[i];
  const auto location = [&](std::string&) { return cmd.Root().Field("pIndirectDeviceAddresses", i); };
  bool skip = false;
  if (!FindBufferHolding(state, address, bytes, 0)) {
    skip |= ReportBuild(ctx, cmd, i, "pIndirectDeviceAddresses-03646", location,
                        "(0x{:x}): pInfos[{}].geometryCount ({}) x pIndirectStrides[{}] ({}) = {} bytes of build "
                        "ranges, [0x{:x}, 0x{:x}), do not lie in one buffer: {}.",
                        address, i, cmd.infos[i].geometryCount, i, cmd.indirect_strides[i], bytes, address,
                        SaturatingAdd(address, bytes), DescribeBuffersAt(state, address));
  }
  if (FindBufferHolding(state, address, 1, 0) &&
      !FindBufferHolding(state, address, 1, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT)) {
    skip |= ReportBuild(ctx, cmd, i, "pIndirectDeviceAddresses-03647", location,
                        "(0x{:x}) comes from a buffer created without VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT: {}.", address,
                        DescribeBuffersAt(state, address));
  }
  return skip;
}

bool ValidateIndirectRanges(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, BufferMemo& memo) {
  if (!cmd.indirect_addresses || !cmd.indirect_strides) return false;
  const VkDeviceSize bytes = SaturatingMul(cmd.infos[i].geometryCount, cmd.indirect_strides[i]);
  if (bytes == 0) return false;  // no range is read
  if (memo.Held(ctx.state, cmd.indirect_addresses[i], bytes, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT)) {
    return false;
  }
  return ReportIndirectRanges(ctx, cmd, i, bytes);
}

}  // namespace

bool ValidateInfoAddresses(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, const ResolvedInfo& r,
                           BufferMemo& memo) {
  // The clean path of a device build (every rule below returns at once) before any call: no stack frame.
  if (InfoAddressesClean(cmd, r)) return false;
  bool skip = ValidateInfoSizes(ctx, cmd, i, r);
  if (cmd.is_host()) return skip;  // host addresses: build_host.h
  skip |= ValidateScratch(ctx, cmd, i, r);
  // Infos in which the command's geometry pass found nothing for these rules are not walked again.
  if (r.walks & kWalkInputReads) skip |= ValidateGeometryInputs(ctx, cmd, i, memo);
  if (cmd.is_indirect()) skip |= ValidateIndirectRanges(ctx, cmd, i, memo);
  return skip;
}

}  // namespace asval
