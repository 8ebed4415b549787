#include "gpu.h"

#include <cstring>
#include <iterator>
#include <stdexcept>
#include <vector>

namespace scene {

namespace {

bool HasExtension(const std::vector<VkExtensionProperties>& extensions, const char* name) {
  for (const VkExtensionProperties& e : extensions) {
    if (std::strcmp(e.extensionName, name) == 0) return true;
  }
  return false;
}

const char* const kDeviceExtensions[] = {VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME,
                                         VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME,
                                         VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME};

}  // namespace

VkPhysicalDevice Gpu::FindRayTracingDevice(VkInstance instance) {
  uint32_t count = 0;
  vkEnumeratePhysicalDevices(instance, &count, nullptr);
  std::vector<VkPhysicalDevice> devices(count);
  vkEnumeratePhysicalDevices(instance, &count, devices.data());
  VkPhysicalDevice best = VK_NULL_HANDLE;
  for (VkPhysicalDevice d : devices) {
    uint32_t n = 0;
    vkEnumerateDeviceExtensionProperties(d, nullptr, &n, nullptr);
    std::vector<VkExtensionProperties> extensions(n);
    vkEnumerateDeviceExtensionProperties(d, nullptr, &n, extensions.data());
    bool all = true;
    for (const char* name : kDeviceExtensions) all = all && HasExtension(extensions, name);
    if (!all) continue;
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(d, &props);
    if (props.apiVersion < VK_API_VERSION_1_2) continue;  // the scene uses 1.2 core features
    if (props.deviceType == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU) return d;
    if (!best) best = d;
  }
  return best;
}

Gpu::Gpu(VkInstance instance, VkPhysicalDevice physical) : physical_(physical) {
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(physical, &props);
  name_ = props.deviceName;

  uint32_t family_count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physical, &family_count, nullptr);
  std::vector<VkQueueFamilyProperties> families(family_count);
  vkGetPhysicalDeviceQueueFamilyProperties(physical, &family_count, families.data());
  bool found = false;
  for (uint32_t i = 0; i < family_count && !found; ++i) {
    if (families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) {
      queue_family_ = i;
      found = true;
    }
  }
  if (!found) throw std::runtime_error("no compute queue");
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queue_info{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queue_info.queueFamilyIndex = queue_family_;
  queue_info.queueCount = 1;
  queue_info.pQueuePriorities = &priority;

  // Only what the scene uses: no ray queries (the H100's driver has none), no host commands.
  VkPhysicalDeviceRayTracingPipelineFeaturesKHR rt_features{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR};
  rt_features.rayTracingPipeline = VK_TRUE;
  VkPhysicalDeviceAccelerationStructureFeaturesKHR as_features{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR, &rt_features};
  as_features.accelerationStructure = VK_TRUE;
  VkPhysicalDeviceVulkan12Features v12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, &as_features};
  v12.bufferDeviceAddress = VK_TRUE;
  VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &v12};
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &queue_info;
  info.enabledExtensionCount = static_cast<uint32_t>(std::size(kDeviceExtensions));
  info.ppEnabledExtensionNames = kDeviceExtensions;
  Check(vkCreateDevice(physical, &info, nullptr, &device_), "vkCreateDevice");
  vkGetDeviceQueue(device_, queue_family_, 0, &queue_);

  VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pool_info.queueFamilyIndex = queue_family_;
  Check(vkCreateCommandPool(device_, &pool_info, nullptr, &pool_), "vkCreateCommandPool");

  vkGetPhysicalDeviceMemoryProperties(physical, &memory_props_);
  as_props_.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR;
  rt_props_.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_PROPERTIES_KHR;
  rt_props_.pNext = &as_props_;
  VkPhysicalDeviceProperties2 props2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &rt_props_};
  vkGetPhysicalDeviceProperties2(physical, &props2);
  rt_props_.pNext = nullptr;
  as_props_.pNext = nullptr;

#define SCENE_LOAD(name) \
  vk_.name = reinterpret_cast<PFN_vk##name>(vkGetDeviceProcAddr(device_, "vk" #name)); \
  if (!vk_.name) throw std::runtime_error("missing entry point vk" #name)
  SCENE_LOAD(CmdBuildAccelerationStructuresKHR);
  SCENE_LOAD(GetAccelerationStructureBuildSizesKHR);
  SCENE_LOAD(CreateAccelerationStructureKHR);
  SCENE_LOAD(DestroyAccelerationStructureKHR);
  SCENE_LOAD(GetAccelerationStructureDeviceAddressKHR);
  SCENE_LOAD(CmdCopyAccelerationStructureKHR);
  SCENE_LOAD(CmdWriteAccelerationStructuresPropertiesKHR);
  SCENE_LOAD(CreateRayTracingPipelinesKHR);
  SCENE_LOAD(GetRayTracingShaderGroupHandlesKHR);
  SCENE_LOAD(CmdTraceRaysKHR);
#undef SCENE_LOAD
  // Optional: present only when the instance enabled VK_EXT_debug_utils.
  vk_.SetDebugUtilsObjectNameEXT = reinterpret_cast<PFN_vkSetDebugUtilsObjectNameEXT>(
      vkGetInstanceProcAddr(instance, "vkSetDebugUtilsObjectNameEXT"));
}

Gpu::~Gpu() {
  vkDeviceWaitIdle(device_);
  vkDestroyCommandPool(device_, pool_, nullptr);
  vkDestroyDevice(device_, nullptr);
}

uint32_t Gpu::FindMemoryType(uint32_t type_bits, Memory memory) const {
  const VkMemoryPropertyFlags wanted = memory == Memory::kHostVisible
                                           ? VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT
                                           : VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
  for (uint32_t i = 0; i < memory_props_.memoryTypeCount; ++i) {
    if ((type_bits & (1u << i)) && (memory_props_.memoryTypes[i].propertyFlags & wanted) == wanted) return i;
  }
  // A device without a DEVICE_LOCAL type for this buffer: any allowed type will do.
  for (uint32_t i = 0; i < memory_props_.memoryTypeCount && memory == Memory::kDeviceLocal; ++i) {
    if (type_bits & (1u << i)) return i;
  }
  throw std::runtime_error("no suitable memory type");
}

VkDeviceAddress Gpu::AddressOf(VkBuffer buffer) const {
  VkBufferDeviceAddressInfo info{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO, nullptr, buffer};
  return vkGetBufferDeviceAddress(device_, &info);
}

VkBuffer Gpu::NewBuffer(VkDeviceSize size, VkBufferUsageFlags usage, VkMemoryRequirements* req) const {
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = size;
  info.usage = usage | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VkBuffer buffer = VK_NULL_HANDLE;
  Check(vkCreateBuffer(device_, &info, nullptr, &buffer), "vkCreateBuffer");
  vkGetBufferMemoryRequirements(device_, buffer, req);
  return buffer;
}

VkDeviceMemory Gpu::AllocateAddressable(VkDeviceSize size, uint32_t type_index) const {
  VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
  flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &flags};
  alloc.allocationSize = size;
  alloc.memoryTypeIndex = type_index;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  Check(vkAllocateMemory(device_, &alloc, nullptr, &memory), "vkAllocateMemory");
  return memory;
}

Buffer Gpu::CreateBuffer(VkDeviceSize size, VkBufferUsageFlags usage, Memory memory) {
  Buffer b;
  b.size = size;
  VkMemoryRequirements req;
  b.buffer = NewBuffer(size, usage, &req);
  b.memory = AllocateAddressable(req.size, FindMemoryType(req.memoryTypeBits, memory));
  Check(vkBindBufferMemory(device_, b.buffer, b.memory, 0), "vkBindBufferMemory");
  if (memory == Memory::kHostVisible) Check(vkMapMemory(device_, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped), "vkMapMemory");
  b.address = AddressOf(b.buffer);
  return b;
}

MemoryBlock Gpu::CreateBlock(VkDeviceSize size, Memory memory) {
  // Ask a probe buffer which memory types suit buffers of the usages the scene binds into blocks.
  VkMemoryRequirements req;
  vkDestroyBuffer(device_,
                  NewBuffer(256,
                            VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR,
                            &req),
                  nullptr);

  MemoryBlock block;
  block.size = size;
  block.type_index = FindMemoryType(req.memoryTypeBits, memory);
  block.memory = AllocateAddressable(size, block.type_index);
  if (memory == Memory::kHostVisible) {
    Check(vkMapMemory(device_, block.memory, 0, VK_WHOLE_SIZE, 0, &block.mapped), "vkMapMemory");
  }
  return block;
}

Buffer Gpu::CreateBufferIn(MemoryBlock& block, VkDeviceSize size, VkBufferUsageFlags usage) {
  Buffer b;
  b.size = size;
  VkMemoryRequirements req;
  b.buffer = NewBuffer(size, usage, &req);
  if (!(req.memoryTypeBits & (1u << block.type_index))) throw std::runtime_error("buffer does not fit the block's memory type");
  const VkDeviceSize offset = AlignUp(block.used, req.alignment);
  if (offset + req.size > block.size) throw std::runtime_error("memory block full");
  Check(vkBindBufferMemory(device_, b.buffer, block.memory, offset), "vkBindBufferMemory");
  block.used = offset + req.size;
  if (block.mapped) b.mapped = static_cast<char*>(block.mapped) + offset;
  b.address = AddressOf(b.buffer);
  return b;  // b.memory stays null: the block owns the memory
}

void Gpu::Destroy(Buffer& b) {
  if (b.buffer) vkDestroyBuffer(device_, b.buffer, nullptr);
  if (b.memory) vkFreeMemory(device_, b.memory, nullptr);
  b = Buffer{};
}

void Gpu::Destroy(MemoryBlock& block) {
  if (block.memory) vkFreeMemory(device_, block.memory, nullptr);
  block = MemoryBlock{};
}

void Gpu::Destroy(PipelineObjects& p) {
  vkDestroyDescriptorPool(device_, p.descriptor_pool, nullptr);
  vkDestroyPipeline(device_, p.pipeline, nullptr);
  vkDestroyPipelineLayout(device_, p.layout, nullptr);
  vkDestroyDescriptorSetLayout(device_, p.set_layout, nullptr);
  p = PipelineObjects{};
}

AccelerationStructure Gpu::CreateAccelerationStructure(VkAccelerationStructureTypeKHR type, VkDeviceSize size,
                                                       const char* name) {
  AccelerationStructure as;
  as.size = size;
  as.storage = CreateBuffer(size, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR, Memory::kDeviceLocal);
  VkAccelerationStructureCreateInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
  info.buffer = as.storage.buffer;
  info.size = size;
  info.type = type;
  Check(vk_.CreateAccelerationStructureKHR(device_, &info, nullptr, &as.handle), "vkCreateAccelerationStructureKHR");
  VkAccelerationStructureDeviceAddressInfoKHR address{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR};
  address.accelerationStructure = as.handle;
  as.address = vk_.GetAccelerationStructureDeviceAddressKHR(device_, &address);
  Name(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, as.handle, name);
  return as;
}

void Gpu::DestroyHandle(AccelerationStructure& as) {
  if (as.handle) vk_.DestroyAccelerationStructureKHR(device_, as.handle, nullptr);
  as.handle = VK_NULL_HANDLE;
}

void Gpu::Destroy(AccelerationStructure& as) {
  DestroyHandle(as);
  Destroy(as.storage);
  as = AccelerationStructure{};
}

VkCommandBuffer Gpu::AllocateCommandBuffer() {
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = pool_;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  VkCommandBuffer cb = VK_NULL_HANDLE;
  Check(vkAllocateCommandBuffers(device_, &alloc, &cb), "vkAllocateCommandBuffers");
  return cb;
}

void Gpu::FreeCommandBuffer(VkCommandBuffer cb) { vkFreeCommandBuffers(device_, pool_, 1, &cb); }

void Gpu::Begin(VkCommandBuffer cb, VkCommandBufferUsageFlags flags) {
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = flags;
  Check(vkBeginCommandBuffer(cb, &begin), "vkBeginCommandBuffer");
}

void Gpu::End(VkCommandBuffer cb) { Check(vkEndCommandBuffer(cb), "vkEndCommandBuffer"); }

VkResult Gpu::SubmitAndWait(std::initializer_list<VkCommandBuffer> command_buffers) {
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = static_cast<uint32_t>(command_buffers.size());
  si.pCommandBuffers = command_buffers.begin();
  const VkResult result = vkQueueSubmit(queue_, 1, &si, VK_NULL_HANDLE);
  // Waiting on the queue rather than a fence: a submission the layer skipped would never signal one.
  Check(vkQueueWaitIdle(queue_), "vkQueueWaitIdle");
  return result;
}

void Gpu::SetName(VkObjectType type, uint64_t handle, const char* name) {
  if (!vk_.SetDebugUtilsObjectNameEXT) return;
  VkDebugUtilsObjectNameInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT};
  info.objectType = type;
  info.objectHandle = handle;
  info.pObjectName = name;
  Check(vk_.SetDebugUtilsObjectNameEXT(device_, &info), "vkSetDebugUtilsObjectNameEXT");
}

}  // namespace scene
