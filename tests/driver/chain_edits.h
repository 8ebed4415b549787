#pragma once
// Edits of pNext chains for the driver below, for the extensions the test driver adds (device_extensions.h): their
// structures are not the driver's, so they are kept out of what it reads. The application's structures are never
// changed, only, for as long as the driver below reads them, the links of its chains (StructureOutOfChain).
#include <vulkan/vulkan.h>

#include <initializer_list>
#include <memory>
#include <vector>

namespace asval_test_driver {

// A structure of one type in an output chain the driver below fills or reads (vkGetPhysicalDeviceFeatures2's,
// vkGetPhysicalDeviceProperties2's, vkCreateDevice's): out of the chain while it does, then put back where it was.
// Only the chain's links change: the structure itself, and the others, are left as they are.
class StructureOutOfChain {
 public:
  StructureOutOfChain(void* head, VkStructureType type);  // head: the structure whose pNext chain is searched
  ~StructureOutOfChain();
  StructureOutOfChain(const StructureOutOfChain&) = delete;
  StructureOutOfChain& operator=(const StructureOutOfChain&) = delete;

  VkBaseOutStructure* structure() const { return structure_; }  // nullptr where the chain had none

 private:
  VkBaseOutStructure* before_ = nullptr;  // the structure whose pNext it was
  VkBaseOutStructure* structure_ = nullptr;
};

// A pNext chain for the driver below without the structures of the given types; the application's structures are
// left as they are. Those after the last one taken out are the application's own; a structure before it needs a copy
// (its pNext changes), which is made for VkOpaqueCaptureDescriptorDataCreateInfoEXT, the one that can come before
// VkAccelerationStructureMotionInfoNV on lavapipe, and any other is left out. A triangles geometry's chain can hold
// only the motion and micromap structures, which are all taken out where they are valid, so no copy is made of it.
class ChainWithout {
 public:
  ChainWithout(const void* chain, std::initializer_list<VkStructureType> types);
  const void* head() const { return head_; }

 private:
  std::vector<std::unique_ptr<unsigned char[]>> copies_;
  const void* head_ = nullptr;
};

}  // namespace asval_test_driver
