#pragma once
// VK_NV_ray_tracing (revision 3) over a driver without it (lavapipe), so that the layers above see and validate the NV
// acceleration-structure commands. The test driver lists the extension, reports its properties (test_driver_api.h),
// takes it out of the extensions the driver below is asked to enable, and implements the structures itself: heap
// objects whose handle is their address, sized by AsvalTestDriverNvMemorySize (test_driver_api.h), bound to memory
// it only records (the listing and the taking out: device_extensions.h).
//
// Nothing is executed, as nothing is traced: vkCmdBuildAccelerationStructureNV, vkCmdCopyAccelerationStructureNV and
// vkCmdWriteAccelerationStructuresPropertiesNV record nothing below, so no structure ever has contents, and the write
// never makes a query available: it stays as its reset left it. Compacted-size query pools are created below as
// VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR pools, which the driver below resets, copies and reads as
// its own: lavapipe answers its acceleration-structure queries as available at any time, so such a query reads as 0
// (VK_SUCCESS, even with VK_QUERY_RESULT_WAIT_BIT); on a driver that tracks availability it would stay not ready. The
// pipeline and trace commands (vkCreateRayTracingPipelinesNV, vkGetRayTracingShaderGroupHandlesNV, vkCompileDeferredNV,
// vkCmdTraceRaysNV) are not implemented: their names go down the chain, where the driver has none.
//
// A device that does not enable the extension sees none of this: its vkGetDeviceProcAddr goes down the chain for the
// NV names and vkCreateQueryPool, and its buffers' usage reaches the driver below unchanged.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>
#include <mutex>
#include <unordered_map>
#include <vector>

namespace asval_test_driver {

// A VkPhysicalDeviceRayTracingPropertiesNV in a vkGetPhysicalDeviceProperties2 chain: out of the chain while the driver
// below fills the others (it does not know the structure), then put back, filled with the test driver's limits.
class RayTracingPropertiesNV {
 public:
  explicit RayTracingPropertiesNV(VkPhysicalDeviceProperties2* properties);
  ~RayTracingPropertiesNV();
  RayTracingPropertiesNV(const RayTracingPropertiesNV&) = delete;
  RayTracingPropertiesNV& operator=(const RayTracingPropertiesNV&) = delete;

 private:
  VkBaseOutStructure* before_ = nullptr;  // the structure whose pNext it was
  VkPhysicalDeviceRayTracingPropertiesNV* properties_ = nullptr;
};

// One device's NV acceleration structures.
class NvRayTracing {
 public:
  // memory_type_bits: every memory type the layers above see.
  NvRayTracing(bool enabled, bool ray_tracing_pipeline_enabled, uint32_t memory_type_bits);
  ~NvRayTracing();
  NvRayTracing(const NvRayTracing&) = delete;
  NvRayTracing& operator=(const NvRayTracing&) = delete;

  bool enabled() const { return enabled_; }
  // vkCreateBuffer: VK_BUFFER_USAGE_RAY_TRACING_BIT_NV is SHADER_BINDING_TABLE_BIT_KHR, which the driver below may be
  // given only with VK_KHR_ray_tracing_pipeline enabled: taken out of the usage it sees when that is not.
  VkBufferUsageFlags UsageBelow(VkBufferUsageFlags usage) const;

  VkResult Create(const VkAccelerationStructureCreateInfoNV& info, VkAccelerationStructureNV* structure);
  void Destroy(VkAccelerationStructureNV structure);
  void MemoryRequirements(const VkAccelerationStructureMemoryRequirementsInfoNV& info,
                          VkMemoryRequirements2* requirements) const;
  VkResult Bind(uint32_t count, const VkBindAccelerationStructureMemoryInfoNV* infos);
  // vkGetAccelerationStructureHandleNV: min(size, 8) bytes of the structure's handle, unique and nonzero.
  VkResult Handle(VkAccelerationStructureNV structure, size_t size, void* data) const;

 private:
  struct Structure {
    VkAccelerationStructureInfoNV info{};  // pGeometries: geometries, pNext chains dropped
    std::vector<VkGeometryNV> geometries;
    VkDeviceSize compacted_size = 0;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkDeviceSize offset = 0;
    uint64_t handle = 0;
  };
  const Structure* Find(VkAccelerationStructureNV structure) const;  // under lock_

  const bool enabled_;
  const bool ray_tracing_pipeline_enabled_;
  const uint32_t memory_type_bits_;
  mutable std::mutex lock_;
  std::unordered_map<VkAccelerationStructureNV, std::unique_ptr<Structure>> structures_;
};

// The device commands the test driver implements for VK_NV_ray_tracing (vkCreateQueryPool among them, for the
// compacted-size query type), or nullptr for any other name.
PFN_vkVoidFunction NvRayTracingFunction(const char* name);

}  // namespace asval_test_driver
