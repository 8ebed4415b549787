#pragma once
// vkkit: the few Vulkan objects the examples and the integration tests need (instance, a ray-tracing
// capable device, buffers with device addresses, acceleration structures, one-shot command buffers).
// Plain code against the loader, written for clarity rather than speed. Failures throw std::runtime_error.
#include <vulkan/vulkan.h>

#include <functional>
#include <string>
#include <vector>

namespace vkkit {

void Check(VkResult result, const char* what);
bool HasDeviceExtension(VkPhysicalDevice gpu, const char* name);

struct InstanceOptions {
  std::vector<std::string> layers;             // enabled in this order (first = closest to the app)
  const void* pNext = nullptr;                 // chained into VkInstanceCreateInfo (messengers, settings)
  bool debug_utils = true;                     // enable VK_EXT_debug_utils
};

// Layers for tests and examples: ASVAL_TEST_LAYERS (':'-separated) if set, else the asval layer alone.
std::vector<std::string> LayersFromEnvironment();

class Instance {
 public:
  explicit Instance(const InstanceOptions& options);
  ~Instance();
  Instance(const Instance&) = delete;
  Instance& operator=(const Instance&) = delete;
  VkInstance handle() const { return instance_; }
  // A physical device with VK_KHR_acceleration_structure (lavapipe in tests), or VK_NULL_HANDLE.
  VkPhysicalDevice FindRayTracingGpu() const;

 private:
  VkInstance instance_ = VK_NULL_HANDLE;
};

struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkDeviceSize size = 0;
  VkDeviceAddress address = 0;
  void* mapped = nullptr;
};

struct AccelerationStructure {
  VkAccelerationStructureKHR handle = VK_NULL_HANDLE;
  Buffer storage;
};

// What a Device enables beyond its own (acceleration structures, deferred host operations, ray queries or the
// ray-tracing pipeline, bufferDeviceAddress).
struct DeviceOptions {
  std::vector<const char*> extensions;
  void* features = nullptr;  // a chain of feature structures, chained after the Device's own
  bool timeline_semaphore = false;  // VkPhysicalDeviceVulkan12Features::timelineSemaphore
  uint32_t queue_count = 1;         // queues of the chosen family, at most what it offers (queue_count())
  bool host_commands = false;  // VkPhysicalDeviceAccelerationStructureFeaturesKHR::accelerationStructureHostCommands
  bool indirect_build = false;  // VkPhysicalDeviceAccelerationStructureFeaturesKHR::accelerationStructureIndirectBuild
};

// Whether the physical device has a device extension.
bool HasDeviceExtension(VkPhysicalDevice gpu, const char* name);

class Device {
 public:
  Device(const Instance& instance, VkPhysicalDevice gpu, const DeviceOptions& options = {});
  ~Device();
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;

  VkDevice handle() const { return device_; }
  VkPhysicalDevice physical_device() const { return gpu_; }
  VkQueue queue() const { return queue_; }
  // Queue i of the chosen family (0: queue()); as many as DeviceOptions::queue_count and the family allow.
  VkQueue queue(uint32_t i) const { return queues_.at(i); }
  uint32_t queue_count() const { return static_cast<uint32_t>(queues_.size()); }
  const VkPhysicalDeviceAccelerationStructurePropertiesKHR& as_properties() const { return as_props_; }

  // Host-visible, coherent, mapped; usage gets SHADER_DEVICE_ADDRESS added.
  Buffer CreateBuffer(VkDeviceSize size, VkBufferUsageFlags usage);
  void Destroy(Buffer& buffer);
  AccelerationStructure CreateAccelerationStructure(VkAccelerationStructureTypeKHR type, VkDeviceSize size);
  void Destroy(AccelerationStructure& as);

  // Records into a fresh command buffer; submits and waits unless submit is false (then only records).
  void OneShot(const std::function<void(VkCommandBuffer)>& record, bool submit = true);
  void SetName(VkObjectType type, uint64_t handle, const char* name);

  PFN_vkCmdBuildAccelerationStructuresKHR CmdBuildAccelerationStructuresKHR = nullptr;
  PFN_vkGetAccelerationStructureBuildSizesKHR GetAccelerationStructureBuildSizesKHR = nullptr;
  PFN_vkCreateAccelerationStructureKHR CreateAccelerationStructureKHR = nullptr;
  PFN_vkDestroyAccelerationStructureKHR DestroyAccelerationStructureKHR = nullptr;
  PFN_vkGetAccelerationStructureDeviceAddressKHR GetAccelerationStructureDeviceAddressKHR = nullptr;
  PFN_vkSetDebugUtilsObjectNameEXT SetDebugUtilsObjectNameEXT = nullptr;

 // The first memory type in type_bits with all of flags and none of excluded; throws if none.
  uint32_t FindMemoryType(uint32_t type_bits, VkMemoryPropertyFlags flags, VkMemoryPropertyFlags excluded = 0) const;

 private:

  VkInstance instance_ = VK_NULL_HANDLE;
  VkPhysicalDevice gpu_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  std::vector<VkQueue> queues_;
  uint32_t queue_family_ = 0;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkPhysicalDeviceMemoryProperties memory_props_{};
  VkPhysicalDeviceAccelerationStructurePropertiesKHR as_props_{};
};

// A bottom-level build of one triangle: everything a vkCmdBuildAccelerationStructuresKHR call needs, with
// the scratch buffer sized by the driver and the scratch address left to the caller.
struct TriangleBuild {
  Buffer vertices;
  Buffer scratch;
  AccelerationStructure blas;
  VkAccelerationStructureGeometryKHR geometry{};
  VkAccelerationStructureBuildGeometryInfoKHR info{};
  VkAccelerationStructureBuildRangeInfoKHR range{};
  VkAccelerationStructureBuildSizesInfoKHR sizes{};

  // scratch_padding: extra scratch bytes so that tests can move the scratch address.
  TriangleBuild(Device& device, VkDeviceSize scratch_padding = 256);
  void Release(Device& device);
  // Sets the scratch address to scratch.address + offset (offset 0 is aligned: buffers are).
  void UseScratchOffset(VkDeviceSize offset);
  void Record(Device& device, VkCommandBuffer cb);
};

}  // namespace vkkit
