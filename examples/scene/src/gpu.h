#pragma once
// The scene's Vulkan device: a queue, ray-tracing features, buffers (dedicated or sub-allocated from one
// block, the way engines' allocators do it), acceleration structures and command buffers. vkkit's Device
// enables no ray-tracing pipeline, so the scene has its own; it reuses vkkit's Buffer and Check.
#include <vulkan/vulkan.h>

#include <initializer_list>
#include <string>

#include "vkkit.h"

namespace scene {

using vkkit::Buffer;
using vkkit::Check;

enum class Memory { kDeviceLocal, kHostVisible };

// One VkDeviceMemory that many buffers are bound into at increasing offsets.
struct MemoryBlock {
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkDeviceSize size = 0;
  VkDeviceSize used = 0;
  uint32_t type_index = 0;
  void* mapped = nullptr;
};

// A compute or ray-tracing pass's pipeline and what it was made from: destroyed together.
struct PipelineObjects {
  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkDescriptorPool descriptor_pool = VK_NULL_HANDLE;
};

struct AccelerationStructure {
  VkAccelerationStructureKHR handle = VK_NULL_HANDLE;
  Buffer storage;
  VkDeviceSize size = 0;
  VkDeviceAddress address = 0;  // vkGetAccelerationStructureDeviceAddressKHR
};

// Device-level entry points of the extensions, loaded once.
struct RayTracingFunctions {
  PFN_vkCmdBuildAccelerationStructuresKHR CmdBuildAccelerationStructuresKHR = nullptr;
  PFN_vkGetAccelerationStructureBuildSizesKHR GetAccelerationStructureBuildSizesKHR = nullptr;
  PFN_vkCreateAccelerationStructureKHR CreateAccelerationStructureKHR = nullptr;
  PFN_vkDestroyAccelerationStructureKHR DestroyAccelerationStructureKHR = nullptr;
  PFN_vkGetAccelerationStructureDeviceAddressKHR GetAccelerationStructureDeviceAddressKHR = nullptr;
  PFN_vkCmdCopyAccelerationStructureKHR CmdCopyAccelerationStructureKHR = nullptr;
  PFN_vkCmdWriteAccelerationStructuresPropertiesKHR CmdWriteAccelerationStructuresPropertiesKHR = nullptr;
  PFN_vkCreateRayTracingPipelinesKHR CreateRayTracingPipelinesKHR = nullptr;
  PFN_vkGetRayTracingShaderGroupHandlesKHR GetRayTracingShaderGroupHandlesKHR = nullptr;
  PFN_vkCmdTraceRaysKHR CmdTraceRaysKHR = nullptr;
  PFN_vkSetDebugUtilsObjectNameEXT SetDebugUtilsObjectNameEXT = nullptr;
};

class Gpu {
 public:
  // The first device with VK_KHR_acceleration_structure and VK_KHR_ray_tracing_pipeline (a discrete GPU
  // first), or VK_NULL_HANDLE.
  static VkPhysicalDevice FindRayTracingDevice(VkInstance instance);

  Gpu(VkInstance instance, VkPhysicalDevice physical);
  ~Gpu();
  Gpu(const Gpu&) = delete;
  Gpu& operator=(const Gpu&) = delete;

  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  const std::string& name() const { return name_; }
  const VkPhysicalDeviceAccelerationStructurePropertiesKHR& as_properties() const { return as_props_; }
  const VkPhysicalDeviceRayTracingPipelinePropertiesKHR& rt_properties() const { return rt_props_; }
  const RayTracingFunctions& vk() const { return vk_; }

  // A buffer with its own memory; host-visible buffers stay mapped. SHADER_DEVICE_ADDRESS is always added.
  Buffer CreateBuffer(VkDeviceSize size, VkBufferUsageFlags usage, Memory memory);
  MemoryBlock CreateBlock(VkDeviceSize size, Memory memory);
  // A buffer bound into `block` at the next suitably aligned offset (its memory stays the block's).
  Buffer CreateBufferIn(MemoryBlock& block, VkDeviceSize size, VkBufferUsageFlags usage);
  void Destroy(Buffer& buffer);  // frees the memory only of dedicated buffers
  void Destroy(MemoryBlock& block);
  void Destroy(PipelineObjects& p);

  AccelerationStructure CreateAccelerationStructure(VkAccelerationStructureTypeKHR type, VkDeviceSize size,
                                                    const char* name);
  // Destroys the handle only; the storage buffer stays alive (fault injection uses this on purpose).
  void DestroyHandle(AccelerationStructure& as);
  void Destroy(AccelerationStructure& as);

  VkCommandBuffer AllocateCommandBuffer();
  void FreeCommandBuffer(VkCommandBuffer cb);
  void Begin(VkCommandBuffer cb, VkCommandBufferUsageFlags flags);
  void End(VkCommandBuffer cb);
  // One vkQueueSubmit of the command buffers in this order, then a wait for the queue. Returns the
  // submission's result: the layer may skip a submission it found invalid (the caller decides).
  VkResult SubmitAndWait(std::initializer_list<VkCommandBuffer> command_buffers);

  void SetName(VkObjectType type, uint64_t handle, const char* name);
  template <typename Handle>
  void Name(VkObjectType type, Handle handle, const std::string& name) {
    SetName(type, reinterpret_cast<uint64_t>(handle), name.c_str());
  }

 private:
  uint32_t FindMemoryType(uint32_t type_bits, Memory memory) const;
  // An unbound buffer with SHADER_DEVICE_ADDRESS added to usage, and its memory requirements.
  VkBuffer NewBuffer(VkDeviceSize size, VkBufferUsageFlags usage, VkMemoryRequirements* req) const;
  // Memory that device addresses may point into.
  VkDeviceMemory AllocateAddressable(VkDeviceSize size, uint32_t type_index) const;
  VkDeviceAddress AddressOf(VkBuffer buffer) const;

  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t queue_family_ = 0;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  std::string name_;
  VkPhysicalDeviceMemoryProperties memory_props_{};
  VkPhysicalDeviceAccelerationStructurePropertiesKHR as_props_{};
  VkPhysicalDeviceRayTracingPipelinePropertiesKHR rt_props_{};
  RayTracingFunctions vk_;
};

inline VkDeviceSize AlignUp(VkDeviceSize value, VkDeviceSize alignment) {
  return (value + alignment - 1) / alignment * alignment;
}

}  // namespace scene
