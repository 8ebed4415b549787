#pragma once
// Whether a structure's memory serves a host command: host-visible and of one instance. The one judge of the
// host build's pInfos-03722..03724 / 03775..03777 and of the host copies' and property writes' buffer-03727,
// 03728, 03730, 03731, 03733 / 03780..03784: each command names the structure and the rule; this says what is
// wrong and how to put it.
#include <vulkan/vulkan.h>

#include <memory>
#include <optional>
#include <string>

#include "check_context.h"
#include "structure_memory.h"

namespace asval {

// A structure's memory as the layer knows it, when a host command's memory rules can be judged on it.
struct StructureHostMemory {
  StructureMemory memory;
  std::shared_ptr<const MemoryState> record;

  bool host_visible() const { return record->property_flags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT; }
  bool multi_instance() const { return record->multi_instance; }
};

// nullopt, counted as unknown state, when the structure, its buffer's binding or its memory is not known (the
// handles family reports what is not live or not bound).
std::optional<StructureHostMemory> HostMemoryOfStructure(const CheckContext& ctx, VkAccelerationStructureKHR handle);

// "VkAccelerationStructureKHR 0x.., whose VkBuffer 0x.. is bound to VkDeviceMemory 0x.. <what is wrong>.": the
// message of the host-visible rule (host_visible_rule) or of the one-instance rule.
std::string DescribeHostMemoryProblem(const StructureHostMemory& host_memory, bool host_visible_rule);

}  // namespace asval
