#include "copies.h"

#include "structure_memory.h"

#include <fmt/format.h>

#include "build_report.h"
#include "history_apply.h"
#include "vk_enum_string.h"

namespace asval {

namespace {

constexpr VkDeviceSize kSerializedDataAlignment = 256;  // pInfo-03740 / pInfo-03743

void CountUnknown(const CheckContext& ctx) {
  ctx.state.checks_skipped_unknown_state.fetch_add(1, std::memory_order_relaxed);
}

// A VUID named without allocating: a structure's whole VUID, or a command's rule as (function, suffix), which
// becomes "VUID-<function>-<suffix>" only when reported.
struct VuidName {
  const char* whole_or_function;
  const char* suffix = nullptr;
  std::string str() const {
    return suffix ? std::string("VUID-") + whole_or_function + "-" + suffix : std::string(whole_or_function);
  }
};

template <typename... Args>
[[gnu::cold, gnu::noinline]] bool Report(const CheckContext& ctx, VkCommandBuffer cb, VkAccelerationStructureKHR as,
                                         const VuidName& vuid, const Location& loc,
                                         fmt::format_string<Args...> format, Args&&... args) {
  return ctx.reporter.Report(Severity::kError, vuid.str(), loc,
                             {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, cb),
                              Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, as)},
                             fmt::format(format, std::forward<Args>(args)...));
}

enum class Bound { kYes, kNo, kUnknown };

// Whether the buffer a structure was created on is bound to memory (sparse buffers and buffers the layer
// never saw: unknown).
Bound StructureBufferBound(const CheckContext& ctx, VkAccelerationStructureKHR as, VkBuffer* buffer_out) {
  std::optional<std::shared_ptr<const AccelerationStructureState>> record = ctx.state.acceleration_structures.find(as);
  if (!record || !*record) return Bound::kUnknown;
  *buffer_out = (*record)->buffer;
  const std::shared_ptr<const BufferState> buffer = BufferOfStructure(ctx.state, **record);
  if (!buffer) return Bound::kUnknown;
  if (buffer->create_flags & VK_BUFFER_CREATE_SPARSE_BINDING_BIT) return Bound::kUnknown;
  return buffer->bound ? Bound::kYes : Bound::kNo;
}

bool CheckBound(const CheckContext& ctx, VkCommandBuffer cb, VkAccelerationStructureKHR as, const VuidName& vuid,
                const Location& loc) {
  VkBuffer buffer = VK_NULL_HANDLE;
  switch (StructureBufferBound(ctx, as, &buffer)) {
    case Bound::kYes: return false;
    case Bound::kUnknown: CountUnknown(ctx); return false;
    case Bound::kNo: break;
  }
  return Report(ctx, cb, as, vuid, loc,
                "(VkAccelerationStructureKHR {}) was created on VkBuffer {}, which is not bound to device memory.",
                Hex(as), Hex(buffer));
}

bool CheckSerializedAlignment(const CheckContext& ctx, VkCommandBuffer cb, VkAccelerationStructureKHR as,
                              const VuidName& vuid, const Location& loc, VkDeviceAddress address) {
  if (address % kSerializedDataAlignment == 0) return false;
  return Report(ctx, cb, as, vuid, loc, "(0x{:x}) is not aligned to 256 bytes; it is {} bytes past a multiple of 256.",
                address, address % kSerializedDataAlignment);
}

bool IsPropertyQueryType(VkQueryType type) {
  return type == VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR ||
         type == VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR ||
         type == VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SIZE_KHR ||
         type == VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_BOTTOM_LEVEL_POINTERS_KHR;
}

}  // namespace

bool ValidateCopyInfo(const CheckContext& ctx, const char* function, VkCommandBuffer cb,
                      const VkCopyAccelerationStructureInfoKHR& info) {
  const Location loc = Location(function).Field("pInfo");
  bool skip = false;
  if (info.mode != VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR &&
      info.mode != VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR) {
    skip |= Report(ctx, cb, info.src, VuidName{"VUID-VkCopyAccelerationStructureInfoKHR-mode-03410"}, loc.Field("mode"),
                   "is {}; a copy between structures must be VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR or "
                   "VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR.",
                   string_VkCopyAccelerationStructureModeKHR(info.mode));
  }
  skip |= CheckBound(ctx, cb, info.src, VuidName{"VUID-VkCopyAccelerationStructureInfoKHR-buffer-03718"},
                     loc.Field("src"));
  skip |= CheckBound(ctx, cb, info.dst, VuidName{"VUID-VkCopyAccelerationStructureInfoKHR-buffer-03719"},
                     loc.Field("dst"));
  const std::optional<MemorySpan> src = AccelerationStructureSpan(ctx.state, info.src);
  const std::optional<MemorySpan> dst = AccelerationStructureSpan(ctx.state, info.dst);
  if (!src || !dst) {
    CountUnknown(ctx);
  } else if (Overlaps(*src, *dst)) {
    skip |= Report(ctx, cb, info.dst, VuidName{"VUID-VkCopyAccelerationStructureInfoKHR-dst-07791"}, loc.Field("dst"),
                   "(VkAccelerationStructureKHR {}) occupies bytes [{}, {}) of VkDeviceMemory {}, which overlap the "
                   "bytes [{}, {}) that src (VkAccelerationStructureKHR {}) occupies.",
                   Hex(info.dst), dst->begin, dst->end, Hex(dst->memory), src->begin, src->end, Hex(info.src));
  }
  return skip;
}

bool ValidateCopyToMemoryInfo(const CheckContext& ctx, const char* function, VkCommandBuffer cb,
                              const VkCopyAccelerationStructureToMemoryInfoKHR& info) {
  const Location loc = Location(function).Field("pInfo");
  bool skip = false;
  if (info.mode != VK_COPY_ACCELERATION_STRUCTURE_MODE_SERIALIZE_KHR) {
    skip |= Report(ctx, cb, info.src, VuidName{"VUID-VkCopyAccelerationStructureToMemoryInfoKHR-mode-03412"},
                   loc.Field("mode"),
                   "is {}; a copy to memory must be VK_COPY_ACCELERATION_STRUCTURE_MODE_SERIALIZE_KHR.",
                   string_VkCopyAccelerationStructureModeKHR(info.mode));
  }
  if (cb) {
    skip |= CheckSerializedAlignment(ctx, cb, info.src, VuidName{function, "pInfo-03740"},
                                     loc.Field("dst").Field("deviceAddress"), info.dst.deviceAddress);
  }
  return skip;
}

bool ValidateCopyMemoryToInfo(const CheckContext& ctx, const char* function, VkCommandBuffer cb,
                              const VkCopyMemoryToAccelerationStructureInfoKHR& info) {
  const Location loc = Location(function).Field("pInfo");
  bool skip = false;
  if (info.mode != VK_COPY_ACCELERATION_STRUCTURE_MODE_DESERIALIZE_KHR) {
    skip |= Report(ctx, cb, info.dst, VuidName{"VUID-VkCopyMemoryToAccelerationStructureInfoKHR-mode-03413"},
                   loc.Field("mode"),
                   "is {}; a copy from memory must be VK_COPY_ACCELERATION_STRUCTURE_MODE_DESERIALIZE_KHR.",
                   string_VkCopyAccelerationStructureModeKHR(info.mode));
  }
  if (cb) {
    skip |= CheckSerializedAlignment(ctx, cb, info.dst, VuidName{function, "pInfo-03743"},
                                     loc.Field("src").Field("deviceAddress"), info.src.deviceAddress);
  }
  return skip;
}

bool ValidateWriteProperties(const CheckContext& ctx, const char* function, VkCommandBuffer cb, uint32_t count,
                             const VkAccelerationStructureKHR* structures, VkQueryType type, VkQueryPool pool,
                             uint32_t first_query) {
  const Location root(function);
  bool skip = false;
  if (!IsPropertyQueryType(type)) {
    skip |= Report(ctx, cb, VK_NULL_HANDLE, VuidName{function, "queryType-06742"}, root.Field("queryType"),
                   "is {}, which is not an acceleration-structure property query type.", string_VkQueryType(type));
  }
  if (!cb) return skip;  // the rest concern the query pool and device execution
  if (std::optional<QueryPoolState> pool_state = ctx.state.history.query_pools.find(pool)) {
    if (pool_state->type != type) {
      skip |= Report(ctx, cb, VK_NULL_HANDLE, VuidName{function, "queryPool-02493"}, root.Field("queryPool"),
                     "(VkQueryPool {}) was created with queryType {}, not the queryType {} of this command.", Hex(pool),
                     string_VkQueryType(pool_state->type), string_VkQueryType(type));
    }
    if (uint64_t{first_query} + count > pool_state->count) {
      skip |= Report(ctx, cb, VK_NULL_HANDLE, VuidName{function, "query-04880"}, root.Field("firstQuery"),
                     "({}) plus accelerationStructureCount ({}) is {}, more than the {} queries of VkQueryPool {}.",
                     first_query, count, uint64_t{first_query} + count, pool_state->count, Hex(pool));
    }
  } else {
    CountUnknown(ctx);
  }
  for (uint32_t i = 0; structures && i < count; ++i) {
    skip |= CheckBound(ctx, cb, structures[i], VuidName{function, "buffer-03736"},
                       root.Field("pAccelerationStructures", i));
  }
  return skip;
}

namespace {

// What each property query type asks of the host command's stride and pData (a VkDeviceSize per structure).
struct PropertyDataRules {
  const char* stride;
  const char* data;
};

PropertyDataRules DataRulesFor(VkQueryType type) {
  switch (type) {
    case VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR: return {"queryType-03448", "queryType-03449"};
    case VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR: return {"queryType-03450", "queryType-03451"};
    case VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SIZE_KHR: return {"queryType-06731", "queryType-06732"};
    case VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_BOTTOM_LEVEL_POINTERS_KHR:
      return {"queryType-06733", "queryType-06734"};
    default: return {nullptr, nullptr};  // queryType-06742's
  }
}

}  // namespace

bool ValidateHostPropertyData(const CheckContext& ctx, const char* function, uint32_t count, VkQueryType type,
                              size_t data_size, const void* data, size_t stride) {
  const Location root(function);
  bool skip = false;
  const PropertyDataRules rules = DataRulesFor(type);
  if (rules.stride && stride % sizeof(VkDeviceSize) != 0) {
    skip |= Report(ctx, VK_NULL_HANDLE, VK_NULL_HANDLE, VuidName{function, rules.stride}, root.Field("stride"),
                   "({}) is not a multiple of sizeof(VkDeviceSize) (8), as queryType {} requires.", stride,
                   string_VkQueryType(type));
  }
  // Nothing is written for no structure; where something is, each value is a VkDeviceSize, which a null or
  // misaligned pointer cannot hold. (That the bytes are the app's, writable, the layer cannot see.)
  const auto address = reinterpret_cast<uintptr_t>(data);
  if (rules.data && count != 0 && (data == nullptr || address % alignof(VkDeviceSize) != 0)) {
    skip |= Report(ctx, VK_NULL_HANDLE, VK_NULL_HANDLE, VuidName{function, rules.data}, root.Field("pData"),
                   "({}) does not point to a VkDeviceSize: {}, as queryType {} requires.", fmt::ptr(data),
                   data == nullptr ? "it is null" : "it is not aligned to 8 bytes", string_VkQueryType(type));
  }
  if (uint64_t{count} * stride > data_size) {
    skip |= Report(ctx, VK_NULL_HANDLE, VK_NULL_HANDLE, VuidName{function, "dataSize-03452"}, root.Field("dataSize"),
                   "({}) is less than accelerationStructureCount ({}) times stride ({}), {}.", data_size, count, stride,
                   uint64_t{count} * stride);
  }
  return skip;
}

}  // namespace asval
