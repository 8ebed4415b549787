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

}  // namespace asval
