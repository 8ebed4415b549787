#include "vkkit.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

namespace vkkit {

void Check(VkResult result, const char* what) {
  if (result != VK_SUCCESS) throw std::runtime_error(std::string(what) + " failed: VkResult " + std::to_string(result));
}

std::vector<std::string> LayersFromEnvironment() {
  const char* env = std::getenv("ASVAL_TEST_LAYERS");
  std::string list = env && *env ? env : "VK_LAYER_ASVAL_as_validation";
  std::vector<std::string> layers;
  size_t start = 0;
  while (start <= list.size()) {
    size_t end = list.find(':', start);
    if (end == std::string::npos) end = list.size();
    if (end > start) layers.push_back(list.substr(start, end - start));
    start = end + 1;
  }
  return layers;
}

Instance::Instance(const InstanceOptions& options) {
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "asval-vkkit";
  app.apiVersion = VK_API_VERSION_1_3;
  std::vector<const char*> layers;
  for (const std::string& l : options.layers) layers.push_back(l.c_str());
  std::vector<const char*> extensions;
  if (options.debug_utils) extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  info.pNext = options.pNext;
  info.pApplicationInfo = &app;
  info.enabledLayerCount = static_cast<uint32_t>(layers.size());
  info.ppEnabledLayerNames = layers.data();
  info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  Check(vkCreateInstance(&info, nullptr, &instance_), "vkCreateInstance");
}

Instance::~Instance() { vkDestroyInstance(instance_, nullptr); }

bool HasDeviceExtension(VkPhysicalDevice gpu, const char* name) {
  uint32_t n = 0;
  vkEnumerateDeviceExtensionProperties(gpu, nullptr, &n, nullptr);
  std::vector<VkExtensionProperties> exts(n);
  vkEnumerateDeviceExtensionProperties(gpu, nullptr, &n, exts.data());
  for (const VkExtensionProperties& e : exts) {
    if (std::strcmp(e.extensionName, name) == 0) return true;
  }
  return false;
}

VkPhysicalDevice Instance::FindRayTracingGpu() const {
  uint32_t count = 0;
  vkEnumeratePhysicalDevices(instance_, &count, nullptr);
  std::vector<VkPhysicalDevice> gpus(count);
  vkEnumeratePhysicalDevices(instance_, &count, gpus.data());
  for (VkPhysicalDevice gpu : gpus) {
    if (HasDeviceExtension(gpu, VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME)) return gpu;
  }
  return VK_NULL_HANDLE;
}

Device::Device(const Instance& instance, VkPhysicalDevice gpu, const DeviceOptions& options)
    : instance_(instance.handle()), gpu_(gpu) {
  uint32_t family_count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(gpu, &family_count, nullptr);
  std::vector<VkQueueFamilyProperties> families(family_count);
  vkGetPhysicalDeviceQueueFamilyProperties(gpu, &family_count, families.data());
  for (uint32_t i = 0; i < family_count; ++i) {
    if (families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) {
      queue_family_ = i;
      break;
    }
  }
  const uint32_t queue_count =
      std::max(1u, std::min(options.queue_count, family_count ? families[queue_family_].queueCount : 1u));
  const std::vector<float> priorities(queue_count, 1.0f);
  VkDeviceQueueCreateInfo queue_info{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queue_info.queueFamilyIndex = queue_family_;
  queue_info.queueCount = queue_count;
  queue_info.pQueuePriorities = priorities.data();

  // rayQuery (or, where the device lacks it, rayTracingPipeline: NVIDIA's driver has no ray queries) is
  // enabled too: the Khronos layer 1.3.239 (stacked below asval in self-validation runs) requires one of
  // them for acceleration-structure size queries.
  const bool has_ray_query = HasDeviceExtension(gpu, VK_KHR_RAY_QUERY_EXTENSION_NAME);
  VkPhysicalDeviceRayQueryFeaturesKHR ray_query{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR};
  ray_query.rayQuery = VK_TRUE;
  VkPhysicalDeviceRayTracingPipelineFeaturesKHR pipeline{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR};
  pipeline.rayTracingPipeline = VK_TRUE;
  VkPhysicalDeviceAccelerationStructureFeaturesKHR as_features{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR,
      has_ray_query ? static_cast<void*>(&ray_query) : static_cast<void*>(&pipeline)};
  as_features.accelerationStructure = VK_TRUE;
  as_features.accelerationStructureHostCommands = options.host_commands ? VK_TRUE : VK_FALSE;
  as_features.accelerationStructureIndirectBuild = options.indirect_build ? VK_TRUE : VK_FALSE;
  ray_query.pNext = options.features;  // the caller's own feature structures, after these
  pipeline.pNext = options.features;
  VkPhysicalDeviceVulkan12Features v12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, &as_features};
  v12.bufferDeviceAddress = VK_TRUE;
  v12.hostQueryReset = VK_TRUE;  // vkResetQueryPool, as programs that compact their structures use it
  v12.timelineSemaphore = options.timeline_semaphore ? VK_TRUE : VK_FALSE;
  std::vector<const char*> extensions = {VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME,
                                         VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME,
                                         has_ray_query ? VK_KHR_RAY_QUERY_EXTENSION_NAME
                                                       : VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME};
  extensions.insert(extensions.end(), options.extensions.begin(), options.extensions.end());
  VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &v12};
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &queue_info;
  info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  Check(vkCreateDevice(gpu, &info, nullptr, &device_), "vkCreateDevice");
  vkGetDeviceQueue(device_, queue_family_, 0, &queue_);
  queues_.assign(queue_count, VK_NULL_HANDLE);
  for (uint32_t i = 0; i < queue_count; ++i) vkGetDeviceQueue(device_, queue_family_, i, &queues_[i]);
  VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pool_info.queueFamilyIndex = queue_family_;
  Check(vkCreateCommandPool(device_, &pool_info, nullptr, &pool_), "vkCreateCommandPool");

  vkGetPhysicalDeviceMemoryProperties(gpu, &memory_props_);
  as_props_.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR;
  VkPhysicalDeviceProperties2 props2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &as_props_};
  vkGetPhysicalDeviceProperties2(gpu, &props2);
  as_props_.pNext = nullptr;

#define VKKIT_LOAD(name) name = reinterpret_cast<PFN_vk##name>(vkGetDeviceProcAddr(device_, "vk" #name))
  VKKIT_LOAD(CmdBuildAccelerationStructuresKHR);
  VKKIT_LOAD(GetAccelerationStructureBuildSizesKHR);
  VKKIT_LOAD(CreateAccelerationStructureKHR);
  VKKIT_LOAD(DestroyAccelerationStructureKHR);
  VKKIT_LOAD(GetAccelerationStructureDeviceAddressKHR);
#undef VKKIT_LOAD
  SetDebugUtilsObjectNameEXT = reinterpret_cast<PFN_vkSetDebugUtilsObjectNameEXT>(
      vkGetInstanceProcAddr(instance_, "vkSetDebugUtilsObjectNameEXT"));
}

Device::~Device() {
  vkDeviceWaitIdle(device_);
  vkDestroyCommandPool(device_, pool_, nullptr);
  vkDestroyDevice(device_, nullptr);
}

uint32_t Device::FindMemoryType(uint32_t type_bits, VkMemoryPropertyFlags flags,
                                VkMemoryPropertyFlags excluded) const {
  for (uint32_t i = 0; i < memory_props_.memoryTypeCount; ++i) {
    const VkMemoryPropertyFlags has = memory_props_.memoryTypes[i].propertyFlags;
    if ((type_bits & (1u << i)) && (has & flags) == flags && !(has & excluded)) return i;
  }
  throw std::runtime_error("no suitable memory type");
}

Buffer Device::CreateBuffer(VkDeviceSize size, VkBufferUsageFlags usage) {
  Buffer b;
  b.size = size;
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = size;
  info.usage = usage | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  Check(vkCreateBuffer(device_, &info, nullptr, &b.buffer), "vkCreateBuffer");
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device_, b.buffer, &req);
  VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
  flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &flags};
  alloc.allocationSize = req.size;
  alloc.memoryTypeIndex =
      FindMemoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  Check(vkAllocateMemory(device_, &alloc, nullptr, &b.memory), "vkAllocateMemory");
  Check(vkBindBufferMemory(device_, b.buffer, b.memory, 0), "vkBindBufferMemory");
  Check(vkMapMemory(device_, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped), "vkMapMemory");
  VkBufferDeviceAddressInfo address{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO, nullptr, b.buffer};
  b.address = vkGetBufferDeviceAddress(device_, &address);
  return b;
}

void Device::Destroy(Buffer& b) {
  if (b.buffer) vkDestroyBuffer(device_, b.buffer, nullptr);
  if (b.memory) vkFreeMemory(device_, b.memory, nullptr);
  b = Buffer{};
}

AccelerationStructure Device::CreateAccelerationStructure(VkAccelerationStructureTypeKHR type, VkDeviceSize size) {
  AccelerationStructure as;
  as.storage = CreateBuffer(size, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR);
  VkAccelerationStructureCreateInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
  info.buffer = as.storage.buffer;
  info.size = size;
  info.type = type;
  Check(CreateAccelerationStructureKHR(device_, &info, nullptr, &as.handle), "vkCreateAccelerationStructureKHR");
  return as;
}

void Device::Destroy(AccelerationStructure& as) {
  if (as.handle) DestroyAccelerationStructureKHR(device_, as.handle, nullptr);
  Destroy(as.storage);
  as = AccelerationStructure{};
}

void Device::OneShot(const std::function<void(VkCommandBuffer)>& record, bool submit) {
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = pool_;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  VkCommandBuffer cb = VK_NULL_HANDLE;
  Check(vkAllocateCommandBuffers(device_, &alloc, &cb), "vkAllocateCommandBuffers");
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  Check(vkBeginCommandBuffer(cb, &begin), "vkBeginCommandBuffer");
  record(cb);
  Check(vkEndCommandBuffer(cb), "vkEndCommandBuffer");
  if (submit) {
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cb;
    Check(vkQueueSubmit(queue_, 1, &si, VK_NULL_HANDLE), "vkQueueSubmit");
    Check(vkQueueWaitIdle(queue_), "vkQueueWaitIdle");
  }
  vkFreeCommandBuffers(device_, pool_, 1, &cb);
}

void Device::SetName(VkObjectType type, uint64_t handle, const char* name) {
  if (!SetDebugUtilsObjectNameEXT) return;
  VkDebugUtilsObjectNameInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT};
  info.objectType = type;
  info.objectHandle = handle;
  info.pObjectName = name;
  Check(SetDebugUtilsObjectNameEXT(device_, &info), "vkSetDebugUtilsObjectNameEXT");
}

TriangleBuild::TriangleBuild(Device& device, VkDeviceSize scratch_padding) {
  const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  vertices = device.CreateBuffer(sizeof(positions),
                                 VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
  std::memcpy(vertices.mapped, positions, sizeof(positions));

  geometry.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR;
  geometry.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
  geometry.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
  auto& tri = geometry.geometry.triangles;
  tri.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
  tri.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
  tri.vertexData.deviceAddress = vertices.address;
  tri.vertexStride = 3 * sizeof(float);
  tri.maxVertex = 2;
  tri.indexType = VK_INDEX_TYPE_NONE_KHR;

  info.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR;
  info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  info.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
  info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  info.geometryCount = 1;
  info.pGeometries = &geometry;
  range.primitiveCount = 1;

  sizes.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR;
  device.GetAccelerationStructureBuildSizesKHR(device.handle(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &info,
                                               &range.primitiveCount, &sizes);
  blas = device.CreateAccelerationStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
                                            sizes.accelerationStructureSize);
  scratch = device.CreateBuffer(sizes.buildScratchSize + scratch_padding, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  info.dstAccelerationStructure = blas.handle;
  info.scratchData.deviceAddress = scratch.address;
}

void TriangleBuild::Release(Device& device) {
  device.Destroy(blas);
  device.Destroy(scratch);
  device.Destroy(vertices);
}

void TriangleBuild::UseScratchOffset(VkDeviceSize offset) { info.scratchData.deviceAddress = scratch.address + offset; }

void TriangleBuild::Record(Device& device, VkCommandBuffer cb) {
  info.pGeometries = &geometry;  // the object may have moved since construction
  const VkAccelerationStructureBuildRangeInfoKHR* ranges = &range;
  device.CmdBuildAccelerationStructuresKHR(cb, 1, &info, &ranges);
}

}  // namespace vkkit
