#include "host_memory.h"

#include <fmt/format.h>

#include "build_report.h"
#include "vk_enum_string.h"

namespace asval {

std::optional<StructureHostMemory> HostMemoryOfStructure(const CheckContext& ctx, VkAccelerationStructureKHR handle) {
  std::optional<StructureMemory> memory = MemoryOfStructure(ctx.state, handle);
  if (!memory || !memory->bound()) {
    CountUnknownState(ctx);  // not a live structure, or not bound: the handles family's rules
    return std::nullopt;
  }
  std::optional<std::shared_ptr<const MemoryState>> record = ctx.state.memories.find(memory->buffer->memory);
  if (!record || !*record) {
    CountUnknownState(ctx);
    return std::nullopt;
  }
  return StructureHostMemory{std::move(*memory), std::move(*record)};
}

[[gnu::cold, gnu::noinline]] std::string DescribeHostMemoryProblem(const StructureHostMemory& host_memory,
                                                                   bool host_visible_rule) {
  const MemoryState& record = *host_memory.record;
  std::string problem;
  if (host_visible_rule) {
    char properties[256];
    string_VkMemoryPropertyFlags(record.property_flags, properties, sizeof(properties));
    problem = fmt::format("of memory type {} ({}), which is not VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT", record.type_index,
                          properties);
  } else {
    problem = "allocated with multiple instances (a device group); a host command needs memory of one instance";
  }
  return fmt::format("VkAccelerationStructureKHR 0x{:x}, whose VkBuffer 0x{:x} is bound to VkDeviceMemory 0x{:x} {}.",
                     reinterpret_cast<uint64_t>(host_memory.memory.structure->handle),
                     reinterpret_cast<uint64_t>(host_memory.memory.buffer->handle),
                     reinterpret_cast<uint64_t>(record.handle), problem);
}

}  // namespace asval
