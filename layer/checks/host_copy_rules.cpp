#include "host_copy_rules.h"

#include <fmt/format.h>

#include <cstdint>
#include <optional>
#include <string>

#include "history_recorder.h"
#include "host_memory.h"

namespace asval {

namespace {

constexpr uintptr_t kSerializedHostAlignment = 16;  // pInfo-03750 / pInfo-03751

template <typename... Args>
[[gnu::cold, gnu::noinline]] bool Report(const CheckContext& ctx, const char* function, const char* suffix,
                                         const Location& loc, fmt::format_string<Args...> format, Args&&... args) {
  return ctx.reporter.Report(Severity::kError, fmt::format("VUID-{}-{}", function, suffix), loc, {},
                             fmt::format(format, std::forward<Args>(args)...));
}

// A host address of serialized bytes: not null (a host pointer: that the bytes are the app's the layer cannot
// see), aligned to 16 bytes.
bool CheckSerializedHostAddress(const CheckContext& ctx, const char* function, const Location& loc, const void* address,
                                const char* pointer_vuid, const char* alignment_vuid) {
  if (address == nullptr) {
    return Report(ctx, function, pointer_vuid, loc, "is null, which is not a host pointer.");
  }
  const auto value = reinterpret_cast<uintptr_t>(address);
  if (value % kSerializedHostAlignment == 0) return false;
  return Report(ctx, function, alignment_vuid, loc,
                "({}) is not aligned to 16 bytes; it is {} bytes past a multiple of 16.", fmt::ptr(address),
                value % kSerializedHostAlignment);
}

// The memory rules of one structure of a host command: host-visible (host_visible_vuid), one instance
// (multi_instance_vuid). `more` (property writes) counts the later structures that break the same rule.
struct MemoryRules {
  const char* host_visible_vuid;
  const char* multi_instance_vuid;
};

bool CheckStructureMemory(const CheckContext& ctx, const char* function, const Location& loc,
                          const StructureHostMemory& host_memory, const MemoryRules& rules, bool host_visible_rule,
                          uint32_t more = 0) {
  return Report(ctx, function, host_visible_rule ? rules.host_visible_vuid : rules.multi_instance_vuid, loc, "is {}{}",
                DescribeHostMemoryProblem(host_memory, host_visible_rule),
                more == 0 ? std::string()
                          : fmt::format(" {} later elements of pAccelerationStructures break this rule too.", more));
}

bool ValidateStructureMemory(const CheckContext& ctx, const char* function, const Location& loc,
                             VkAccelerationStructureKHR handle, const MemoryRules& rules) {
  const std::optional<StructureHostMemory> host_memory = HostMemoryOfStructure(ctx, handle);
  if (!host_memory) return false;  // unknown: counted
  bool skip = false;
  if (!host_memory->host_visible()) skip |= CheckStructureMemory(ctx, function, loc, *host_memory, rules, true);
  if (host_memory->multi_instance()) skip |= CheckStructureMemory(ctx, function, loc, *host_memory, rules, false);
  return skip;
}

}  // namespace

bool ValidateHostCopyDeferred(const CheckContext& ctx, const char* function, VkDeferredOperationKHR deferred) {
  if (deferred == VK_NULL_HANDLE || !HasDeferredOps(ctx.state, deferred)) return false;
  return Report(ctx, function, "deferredOperation-03678", Location(function).Field("deferredOperation"),
                "(VkDeferredOperationKHR 0x{:x}) is still associated with an earlier host command that returned "
                "VK_OPERATION_DEFERRED_KHR and has not been seen to complete (vkDeferredOperationJoinKHR returning "
                "VK_SUCCESS, or vkGetDeferredOperationResultKHR returning other than VK_NOT_READY).",
                reinterpret_cast<uint64_t>(deferred));
}

bool ValidateHostCopyStructures(const CheckContext& ctx, const VkCopyAccelerationStructureInfoKHR& info) {
  const char* function = "vkCopyAccelerationStructureKHR";
  const Location pinfo = Location(function).Field("pInfo");
  bool skip = ValidateStructureMemory(ctx, function, pinfo.Field("src"), info.src, {"buffer-03727", "buffer-03780"});
  skip |= ValidateStructureMemory(ctx, function, pinfo.Field("dst"), info.dst, {"buffer-03728", "buffer-03781"});
  return skip;
}

bool ValidateHostCopyToMemory(const CheckContext& ctx, const VkCopyAccelerationStructureToMemoryInfoKHR& info) {
  const char* function = "vkCopyAccelerationStructureToMemoryKHR";
  const Location pinfo = Location(function).Field("pInfo");
  bool skip = ValidateStructureMemory(ctx, function, pinfo.Field("src"), info.src, {"buffer-03731", "buffer-03783"});
  skip |= CheckSerializedHostAddress(ctx, function, pinfo.Field("dst").Field("hostAddress"), info.dst.hostAddress,
                                     "pInfo-03732", "pInfo-03751");
  return skip;
}

bool ValidateHostCopyMemoryTo(const CheckContext& ctx, const VkCopyMemoryToAccelerationStructureInfoKHR& info) {
  const char* function = "vkCopyMemoryToAccelerationStructureKHR";
  const Location pinfo = Location(function).Field("pInfo");
  bool skip = ValidateStructureMemory(ctx, function, pinfo.Field("dst"), info.dst, {"buffer-03730", "buffer-03782"});
  skip |= CheckSerializedHostAddress(ctx, function, pinfo.Field("src").Field("hostAddress"), info.src.hostAddress,
                                     "pInfo-03729", "pInfo-03750");
  return skip;
}

bool ValidateHostPropertyStructures(const CheckContext& ctx, uint32_t count,
                                    const VkAccelerationStructureKHR* structures) {
  const char* function = "vkWriteAccelerationStructuresPropertiesKHR";
  if (structures == nullptr) return false;
  // One report per rule, at the first structure that breaks it; the later ones counted in its message.
  uint32_t first[2] = {UINT32_MAX, UINT32_MAX};  // host-visible, one instance
  uint32_t breaking[2] = {0, 0};
  std::optional<StructureHostMemory> first_memory[2];
  for (uint32_t k = 0; k < count; ++k) {
    std::optional<StructureHostMemory> host_memory = HostMemoryOfStructure(ctx, structures[k]);
    if (!host_memory) continue;  // unknown: counted
    const bool broken[2] = {!host_memory->host_visible(), host_memory->multi_instance()};
    for (int rule = 0; rule < 2; ++rule) {
      if (!broken[rule]) continue;
      if (breaking[rule]++ == 0) {
        first[rule] = k;
        first_memory[rule] = host_memory;
      }
    }
  }
  bool skip = false;
  const MemoryRules rules{"buffer-03733", "buffer-03784"};
  for (int rule = 0; rule < 2; ++rule) {
    if (breaking[rule] == 0) continue;
    skip |= CheckStructureMemory(ctx, function, Location(function).Field("pAccelerationStructures", first[rule]),
                                 *first_memory[rule], rules, rule == 0, breaking[rule] - 1);
  }
  return skip;
}

}  // namespace asval
