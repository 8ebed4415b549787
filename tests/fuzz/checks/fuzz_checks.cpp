// Fuzz target over the record-time checks of every rule family (issue 14): a synthetic device's shadow state, then
// one to four commands decoded from the input (device, indirect and host builds, copies, serialization, property
// writes), each run through the layer's own validation as its hook runs it, with the families the input enables
// (mostly all). Host commands that succeed change the build history the next command is checked against, as the
// hooks do. Findings: a crash, a sanitizer report, a hang, or a malformed or non-deterministic message
// (check_runner.h).
#include <cstdint>
#include <vector>

#include "build_call.h"
#include "build_validation.h"
#include "byte_source.h"
#include "check_runner.h"
#include "copies.h"
#include "history_host.h"
#include "history_recorder.h"
#include "synthetic_device.h"

namespace asval::fuzz {

namespace {

constexpr uint32_t kAllFamilies = kCheckFeatures | kCheckHandles | kCheckStructure | kCheckAlignment | kCheckAddresses |
                                  kCheckAliasing | kCheckHost | kCheckCopies | kCheckHistory;

VkResult HostResult(ByteSource& in, VkDeferredOperationKHR deferred) {
  if (deferred != VK_NULL_HANDLE && in.Bit()) return VK_OPERATION_DEFERRED_KHR;
  return in.OneIn(8) ? VK_ERROR_OUT_OF_HOST_MEMORY : VK_SUCCESS;
}

VkCopyAccelerationStructureModeKHR ChooseCopyMode(ByteSource& in) {
  if (in.OneIn(4) && in.Bit()) return in.AnyEnum<VkCopyAccelerationStructureModeKHR>();
  return static_cast<VkCopyAccelerationStructureModeKHR>(in.Below(4));
}

void RunBuild(ByteSource& in, SyntheticDevice& device, CheckRunner& runner, BuildCommandKind kind) {
  const BuildCall call(in, device, kind);
  const BuildCommand& cmd = call.command();
  const bool skip = runner.Run([&](const CheckContext& ctx) { return ValidateBuildCommand(ctx, cmd); });
  if (skip || !cmd.is_host()) return;  // device builds change the history at submission
  // As the host build's hook does, past maxGeometryCount included (the recorder stops there: geometry_limit.h).
  FinishHostOps(device.state(),
                HostBuildOps(cmd.info_count, cmd.infos, cmd.ranges, nullptr, nullptr,
                             device.state().properties.acceleration_structure.maxGeometryCount),
                cmd.deferred_operation, HostResult(in, cmd.deferred_operation));
}

// A host copy runs the copies family and the history rules over its operations, as the hook does.
template <typename Validate>
bool RunHostRules(CheckRunner& runner, const DeviceState& state, const OpBatch* batch, const char* function,
                  const Validate& validate) {
  return runner.Run([&](const CheckContext& ctx) {
    bool skip = ctx.Enabled(kCheckCopies) && validate(ctx);
    if (batch && state.history_tracked) skip |= ValidateHostOps(ctx, *batch, function);
    return skip;
  });
}

void RunCopy(ByteSource& in, SyntheticDevice& device, CheckRunner& runner) {
  VkCopyAccelerationStructureInfoKHR info{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_INFO_KHR};
  info.src = device.Structure(in);
  info.dst = device.Structure(in);
  info.mode = ChooseCopyMode(in);
  if (in.Bit()) {
    const VkCommandBuffer cb = device.CommandBuffer(in);
    runner.Run([&](const CheckContext& ctx) {
      return ctx.Enabled(kCheckCopies) && ValidateCopyInfo(ctx, "vkCmdCopyAccelerationStructureKHR", cb, info);
    });
    return;
  }
  const char* function = "vkCopyAccelerationStructureKHR";
  const OpBatch batch = HostCopyOps(info);
  const bool skip = RunHostRules(runner, device.state(), &batch, function, [&](const CheckContext& ctx) {
    return ValidateCopyInfo(ctx, function, VK_NULL_HANDLE, info);
  });
  if (skip) return;
  const VkDeferredOperationKHR deferred = device.DeferredOperation(in);
  FinishHostOps(device.state(), HostCopyOps(info), deferred, HostResult(in, deferred));
}

// Serialization and deserialization: the record-time rules only. Their history operations read the serialized
// bytes, which only a driver writes (the history fuzz target's concern).
void RunSerialization(ByteSource& in, SyntheticDevice& device, CheckRunner& runner) {
  const bool host = in.Bit();
  const VkCommandBuffer cb = host ? VK_NULL_HANDLE : device.CommandBuffer(in);
  if (in.Bit()) {
    VkCopyAccelerationStructureToMemoryInfoKHR info{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_TO_MEMORY_INFO_KHR};
    info.src = device.Structure(in);
    info.mode = ChooseCopyMode(in);
    if (host) {
      info.dst.hostAddress = device.arena().Place(in, 64);
    } else {
      info.dst.deviceAddress = device.DeviceAddress(in);
    }
    const char* function =
        host ? "vkCopyAccelerationStructureToMemoryKHR" : "vkCmdCopyAccelerationStructureToMemoryKHR";
    RunHostRules(runner, device.state(), nullptr, function,
                 [&](const CheckContext& ctx) { return ValidateCopyToMemoryInfo(ctx, function, cb, info); });
    return;
  }
  VkCopyMemoryToAccelerationStructureInfoKHR info{VK_STRUCTURE_TYPE_COPY_MEMORY_TO_ACCELERATION_STRUCTURE_INFO_KHR};
  info.dst = device.Structure(in);
  info.mode = ChooseCopyMode(in);
  if (host) {
    info.src.hostAddress = device.arena().Place(in, 64);
  } else {
    info.src.deviceAddress = device.DeviceAddress(in);
  }
  const char* function = host ? "vkCopyMemoryToAccelerationStructureKHR" : "vkCmdCopyMemoryToAccelerationStructureKHR";
  RunHostRules(runner, device.state(), nullptr, function,
               [&](const CheckContext& ctx) { return ValidateCopyMemoryToInfo(ctx, function, cb, info); });
}

void RunWriteProperties(ByteSource& in, SyntheticDevice& device, CheckRunner& runner) {
  std::vector<VkAccelerationStructureKHR> structures(in.Below(6));
  for (VkAccelerationStructureKHR& s : structures) s = device.Structure(in);
  const VkQueryType types[] = {VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR,
                               VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR,
                               VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SIZE_KHR,
                               VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_BOTTOM_LEVEL_POINTERS_KHR,
                               VK_QUERY_TYPE_OCCLUSION, VK_QUERY_TYPE_TIMESTAMP};
  const VkQueryType type = in.OneIn(8) ? in.AnyEnum<VkQueryType>() : in.Pick(types);
  const uint32_t count = static_cast<uint32_t>(structures.size());
  const VkAccelerationStructureKHR* data = structures.empty() && in.Bit() ? nullptr : structures.data();
  if (in.Bit()) {
    const VkCommandBuffer cb = device.CommandBuffer(in);
    const VkQueryPool pool = device.QueryPool(in);
    const uint32_t first = in.Bit() ? in.Below(8) : in.U32();
    runner.Run([&](const CheckContext& ctx) {
      return ctx.Enabled(kCheckCopies) &&
             ValidateWriteProperties(ctx, "vkCmdWriteAccelerationStructuresPropertiesKHR", cb, count, data, type, pool,
                                     first);
    });
    return;
  }
  const char* function = "vkWriteAccelerationStructuresPropertiesKHR";
  const OpBatch batch = HostWritePropertiesOps(count, data, type);
  RunHostRules(runner, device.state(), &batch, function, [&](const CheckContext& ctx) {
    return ValidateWriteProperties(ctx, function, VK_NULL_HANDLE, count, data, type, VK_NULL_HANDLE, 0);
  });
}

}  // namespace

}  // namespace asval::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace asval;
  using namespace asval::fuzz;
  ByteSource in(data, size);
  SyntheticDevice device(in);
  const uint32_t families = in.OneIn(4) ? in.U16() : kAllFamilies;  // one family alone, some, all, unknown bits
  const bool skip_answer = in.OneIn(8);
  CheckRunner runner(device.state(), families, skip_answer);
  const uint32_t commands = 1 + in.Below(4);
  for (uint32_t k = 0; k < commands; ++k) {
    switch (in.Below(12)) {
      case 0:
      case 1:
      case 2: RunBuild(in, device, runner, BuildCommandKind::kCmdBuild); break;
      case 3:
      case 4: RunBuild(in, device, runner, BuildCommandKind::kCmdBuildIndirect); break;
      case 5:
      case 6:
      case 7: RunBuild(in, device, runner, BuildCommandKind::kHostBuild); break;
      case 8: RunCopy(in, device, runner); break;
      case 9:
      case 10: RunSerialization(in, device, runner); break;
      default: RunWriteProperties(in, device, runner); break;
    }
  }
  return 0;
}
