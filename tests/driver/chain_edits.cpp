#include "chain_edits.h"

#include <algorithm>
#include <cstring>

namespace asval_test_driver {
namespace {

// The size of a structure ChainWithout copies, or 0 for one it leaves out.
size_t CopiedSize(VkStructureType type) {
  switch (type) {
    case VK_STRUCTURE_TYPE_OPAQUE_CAPTURE_DESCRIPTOR_DATA_CREATE_INFO_EXT:
      return sizeof(VkOpaqueCaptureDescriptorDataCreateInfoEXT);
    default:
      return 0;
  }
}

}  // namespace

StructureOutOfChain::StructureOutOfChain(void* head, VkStructureType type) {
  for (auto* s = static_cast<VkBaseOutStructure*>(head); s->pNext != nullptr; s = s->pNext) {
    if (s->pNext->sType == type) {
      before_ = s;
      structure_ = s->pNext;
      before_->pNext = structure_->pNext;
      return;
    }
  }
}

StructureOutOfChain::~StructureOutOfChain() {
  if (structure_ != nullptr) before_->pNext = structure_;  // its own pNext was left as it was
}

ChainWithout::ChainWithout(const void* chain, std::initializer_list<VkStructureType> types) : head_(chain) {
  const auto taken_out = [&types](VkStructureType type) {
    return std::find(types.begin(), types.end(), type) != types.end();
  };
  const VkBaseInStructure* last = nullptr;
  for (auto* s = static_cast<const VkBaseInStructure*>(chain); s != nullptr; s = s->pNext) {
    if (taken_out(s->sType)) last = s;
  }
  if (last == nullptr) return;
  std::vector<const VkBaseInStructure*> kept;  // before `last`
  for (auto* s = static_cast<const VkBaseInStructure*>(chain); s != last; s = s->pNext) {
    if (!taken_out(s->sType) && CopiedSize(s->sType) != 0) kept.push_back(s);
  }
  head_ = last->pNext;
  for (auto s = kept.rbegin(); s != kept.rend(); ++s) {  // linked from the end
    const size_t size = CopiedSize((*s)->sType);
    copies_.push_back(std::make_unique<unsigned char[]>(size));
    std::memcpy(copies_.back().get(), *s, size);
    reinterpret_cast<VkBaseInStructure*>(copies_.back().get())->pNext = static_cast<const VkBaseInStructure*>(head_);
    head_ = copies_.back().get();
  }
}

}  // namespace asval_test_driver
