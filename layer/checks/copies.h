#pragma once
// The copies family: rules of the copy, serialization and property-query commands that the arguments and the
// shadow state decide when the command is recorded (or, for host commands, called). Each returns true when a
// callback asked that the call not be passed down.
//   VkCopyAccelerationStructureInfoKHR: mode-03410, buffer-03718, buffer-03719, dst-07791
//   VkCopyAccelerationStructureToMemoryInfoKHR: mode-03412; vkCmdCopyAccelerationStructureToMemoryKHR-pInfo-03740
//   VkCopyMemoryToAccelerationStructureInfoKHR: mode-03413; vkCmdCopyMemoryToAccelerationStructureKHR-pInfo-03743
//   vkCmdWriteAccelerationStructuresPropertiesKHR: queryType-06742, queryPool-02493, query-04880, buffer-03736
//   vkWriteAccelerationStructuresPropertiesKHR: queryType-06742; stride and pData per query type (03448 / 03449
//   compacted size, 03450 / 03451 serialization size, 06731 / 06732 size, 06733 / 06734 bottom-level pointers),
//   dataSize-03452
// (dst-03561 needs the source's serialization size for its current contents: checked at submission, see
// update_rules.h.)
#include <vulkan/vulkan.h>

#include "check_context.h"

namespace asval {

// function: "vkCmdCopyAccelerationStructureKHR" or "vkCopyAccelerationStructureKHR"; cb: null for host calls.
bool ValidateCopyInfo(const CheckContext& ctx, const char* function, VkCommandBuffer cb,
                      const VkCopyAccelerationStructureInfoKHR& info);
bool ValidateCopyToMemoryInfo(const CheckContext& ctx, const char* function, VkCommandBuffer cb,
                              const VkCopyAccelerationStructureToMemoryInfoKHR& info);
bool ValidateCopyMemoryToInfo(const CheckContext& ctx, const char* function, VkCommandBuffer cb,
                              const VkCopyMemoryToAccelerationStructureInfoKHR& info);
// pool is VK_NULL_HANDLE for the host command.
bool ValidateWriteProperties(const CheckContext& ctx, const char* function, VkCommandBuffer cb, uint32_t count,
                             const VkAccelerationStructureKHR* structures, VkQueryType type, VkQueryPool pool,
                             uint32_t first_query);
// vkWriteAccelerationStructuresPropertiesKHR's host data: stride and pData as the query type requires, dataSize.
bool ValidateHostPropertyData(const CheckContext& ctx, const char* function, uint32_t count, VkQueryType type,
                              size_t data_size, const void* data, size_t stride);

}  // namespace asval
