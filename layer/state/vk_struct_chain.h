#pragma once
// Walking pNext chains without assuming the headers know every structure in them.
#include <vulkan/vulkan.h>

namespace asval {

template <typename T>
const T* FindInChain(const void* pNext, VkStructureType type) {
  for (auto* s = static_cast<const VkBaseInStructure*>(pNext); s; s = s->pNext) {
    if (s->sType == type) return reinterpret_cast<const T*>(s);
  }
  return nullptr;
}

// VK_KHR_maintenance5's VkBufferUsageFlags2CreateInfoKHR is newer than the 1.3.239 headers. When an app chains
// it, its 64-bit usage replaces VkBufferCreateInfo::usage, so the layer must read it to know the real usage.
constexpr VkStructureType kBufferUsageFlags2CreateInfo = static_cast<VkStructureType>(1000470006);
struct BufferUsageFlags2CreateInfo {
  VkStructureType sType;
  const void* pNext;
  uint64_t usage;
};

}  // namespace asval
