#pragma once
// The one change the layer makes to an app's create info (issue 12; issue 25, item 7): a build-input buffer gets
// TRANSFER_SRC, so that the capture may copy from it where its memory is a dedicated allocation (the layer cannot
// bind a buffer of its own there, memory_aliases.h). The memory requirements the app asks for must be those of the
// buffer it gets, so vkCreateBuffer and vkGetDeviceBufferMemoryRequirements(KHR) (maintenance4: how VMA sizes its
// pools) both pass down the create info this says.
#include <vulkan/vulkan.h>

#include "vk_struct_chain.h"

namespace asval {

// Whether a buffer created with `info` gets TRANSFER_SRC (capture on). Left alone: a usage given by
// VkBufferUsageFlags2CreateInfoKHR (VK_KHR_maintenance5, newer than the layer's headers), and an external buffer
// (its usage is part of what the app asked external-memory support for; its memory cannot be aliased either).
inline bool AddsCopyUsage(bool capture_on, const VkBufferCreateInfo& info) {
  if (!capture_on || !(info.usage & VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR) ||
      (info.usage & VK_BUFFER_USAGE_TRANSFER_SRC_BIT)) {
    return false;
  }
  if (FindInChain<BufferUsageFlags2CreateInfo>(info.pNext, kBufferUsageFlags2CreateInfo)) return false;
  const auto* external = FindInChain<VkExternalMemoryBufferCreateInfo>(
      info.pNext, VK_STRUCTURE_TYPE_EXTERNAL_MEMORY_BUFFER_CREATE_INFO);
  return !external || external->handleTypes == 0;
}

// Whether the shadow record of a buffer created with `info` (as passed down) says it is copyable: TRANSFER_SRC in
// the usage that counts (a VkBufferUsageFlags2CreateInfoKHR's replaces VkBufferCreateInfo::usage).
inline bool CreatedCopyable(const VkBufferCreateInfo& info) {
  if (const auto* usage2 = FindInChain<BufferUsageFlags2CreateInfo>(info.pNext, kBufferUsageFlags2CreateInfo)) {
    return (usage2->usage & VK_BUFFER_USAGE_TRANSFER_SRC_BIT) != 0;
  }
  return (info.usage & VK_BUFFER_USAGE_TRANSFER_SRC_BIT) != 0;
}

}  // namespace asval
