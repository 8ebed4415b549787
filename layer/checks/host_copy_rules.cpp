#include "host_copy_rules.h"

#include <fmt/format.h>

#include <cstdint>
#include <string>

#include "history_recorder.h"

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

}  // namespace

bool ValidateHostCopyDeferred(const CheckContext& ctx, const char* function, VkDeferredOperationKHR deferred) {
  if (deferred == VK_NULL_HANDLE || !HasDeferredOps(ctx.state, deferred)) return false;
  return Report(ctx, function, "deferredOperation-03678", Location(function).Field("deferredOperation"),
                "(VkDeferredOperationKHR 0x{:x}) is still associated with an earlier host command that returned "
                "VK_OPERATION_DEFERRED_KHR and has not been seen to complete (vkDeferredOperationJoinKHR returning "
                "VK_SUCCESS, or vkGetDeferredOperationResultKHR returning other than VK_NOT_READY).",
                reinterpret_cast<uint64_t>(deferred));
}

bool ValidateHostCopyToMemory(const CheckContext& ctx, const VkCopyAccelerationStructureToMemoryInfoKHR& info) {
  const char* function = "vkCopyAccelerationStructureToMemoryKHR";
  return CheckSerializedHostAddress(ctx, function, Location(function).Field("pInfo").Field("dst").Field("hostAddress"),
                                    info.dst.hostAddress, "pInfo-03732", "pInfo-03751");
}

bool ValidateHostCopyMemoryTo(const CheckContext& ctx, const VkCopyMemoryToAccelerationStructureInfoKHR& info) {
  const char* function = "vkCopyMemoryToAccelerationStructureKHR";
  return CheckSerializedHostAddress(ctx, function, Location(function).Field("pInfo").Field("src").Field("hostAddress"),
                                    info.src.hostAddress, "pInfo-03729", "pInfo-03750");
}

}  // namespace asval
