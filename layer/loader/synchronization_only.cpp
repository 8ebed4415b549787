#include "synchronization_only.h"

#include <cstring>

namespace asval {

namespace {

bool HoldsDeviceGroup(const void* next) {
  for (auto s = static_cast<const VkBaseInStructure*>(next); s; s = s->pNext) {
    if (s->sType == VK_STRUCTURE_TYPE_DEVICE_GROUP_SUBMIT_INFO) return true;
  }
  return false;
}

}  // namespace

EmptiedSubmits::EmptiedSubmits(uint32_t count, const VkSubmitInfo* submits) {
  if (count == 0 || !submits) return;
  submits_.assign(submits, submits + count);
  chains_.resize(count);
  for (uint32_t i = 0; i < count; ++i) {
    VkSubmitInfo& s = submits_[i];
    s.commandBufferCount = 0;
    s.pCommandBuffers = nullptr;
    if (HoldsDeviceGroup(s.pNext)) s.pNext = RebuiltChain(s.pNext, chains_[i]);
  }
}

const void* EmptiedSubmits::RebuiltChain(const void* next, Chain& chain) {
  VkBaseOutStructure* head = nullptr;
  VkBaseOutStructure** tail = &head;
  const auto link = [&](auto& copy, const VkBaseInStructure* from) {
    if (copy.sType == from->sType) return;  // the same structure twice (invalid): linked once, never a loop
    std::memcpy(&copy, from, sizeof(copy));
    copy.pNext = nullptr;
    *tail = reinterpret_cast<VkBaseOutStructure*>(&copy);
    tail = &(*tail)->pNext;
  };
  for (auto s = static_cast<const VkBaseInStructure*>(next); s; s = s->pNext) {
    switch (s->sType) {
      case VK_STRUCTURE_TYPE_DEVICE_GROUP_SUBMIT_INFO:
        link(chain.device_group, s);
        chain.device_group.commandBufferCount = 0;
        chain.device_group.pCommandBufferDeviceMasks = nullptr;
        break;
      case VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO:
        link(chain.timeline, s);
        break;
      case VK_STRUCTURE_TYPE_PROTECTED_SUBMIT_INFO:
        link(chain.protected_submit, s);
        break;
      case VK_STRUCTURE_TYPE_PERFORMANCE_QUERY_SUBMIT_INFO_KHR:
        link(chain.performance_query, s);
        break;
      default:  // the rest describe command buffers or mark frames for tools (Windows' keyed mutexes and D3D12
        break;    // fences would order it, but the layer is not built there)
    }
  }
  return head;
}

EmptiedSubmits2::EmptiedSubmits2(uint32_t count, const VkSubmitInfo2* submits) {
  if (count == 0 || !submits) return;
  submits_.assign(submits, submits + count);
  for (VkSubmitInfo2& s : submits_) {
    s.commandBufferInfoCount = 0;
    s.pCommandBufferInfos = nullptr;
  }
}

}  // namespace asval
