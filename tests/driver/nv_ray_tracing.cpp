#include "nv_ray_tracing.h"

#include <algorithm>
#include <atomic>
#include <cstring>

#include "driver_dispatch.h"
#include "test_driver_api.h"

namespace asval_test_driver {
namespace {

// The sizes are constants where the counts are (test_driver_api.h): 1024 + 128 * 3 = 1408, up to 1536.
static_assert(AsvalTestDriverNvMemorySize(VK_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_TYPE_OBJECT_NV, 3) == 1536);
static_assert(AsvalTestDriverNvMemorySize(VK_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_TYPE_OBJECT_NV, 3, 1000) ==
              1024);

// The values vkGetAccelerationStructureHandleNV gives: never reused, in this process, so that two structures (of any
// devices, alive or not) never share one.
std::atomic<uint64_t> g_next_handle{1};

}  // namespace

RayTracingPropertiesNV::RayTracingPropertiesNV(VkPhysicalDeviceProperties2* properties) {
  for (auto* s = reinterpret_cast<VkBaseOutStructure*>(properties); s->pNext != nullptr; s = s->pNext) {
    if (s->pNext->sType == VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PROPERTIES_NV) {
      before_ = s;
      properties_ = reinterpret_cast<VkPhysicalDeviceRayTracingPropertiesNV*>(s->pNext);
      before_->pNext = s->pNext->pNext;
      return;
    }
  }
}

RayTracingPropertiesNV::~RayTracingPropertiesNV() {
  if (properties_ == nullptr) return;
  before_->pNext = reinterpret_cast<VkBaseOutStructure*>(properties_);  // its own pNext was left as it was
  properties_->shaderGroupHandleSize = kAsvalTestDriverNvShaderGroupHandleSize;
  properties_->maxRecursionDepth = kAsvalTestDriverNvMaxRecursionDepth;
  properties_->maxShaderGroupStride = kAsvalTestDriverNvMaxShaderGroupStride;
  properties_->shaderGroupBaseAlignment = kAsvalTestDriverNvShaderGroupBaseAlignment;
  properties_->maxGeometryCount = kAsvalTestDriverNvMaxGeometryCount;
  properties_->maxInstanceCount = kAsvalTestDriverNvMaxInstanceCount;
  properties_->maxTriangleCount = kAsvalTestDriverNvMaxTriangleCount;
  properties_->maxDescriptorSetAccelerationStructures = kAsvalTestDriverNvMaxDescriptorSetAccelerationStructures;
}

NvRayTracing::NvRayTracing(bool enabled, bool ray_tracing_pipeline_enabled, uint32_t memory_type_bits)
    : enabled_(enabled),
      ray_tracing_pipeline_enabled_(ray_tracing_pipeline_enabled),
      memory_type_bits_(memory_type_bits) {}

NvRayTracing::~NvRayTracing() = default;  // structures the application did not destroy go with the device

VkBufferUsageFlags NvRayTracing::UsageBelow(VkBufferUsageFlags usage) const {
  if (!enabled_ || ray_tracing_pipeline_enabled_) return usage;
  return usage & ~static_cast<VkBufferUsageFlags>(VK_BUFFER_USAGE_RAY_TRACING_BIT_NV);
}

VkResult NvRayTracing::Create(const VkAccelerationStructureCreateInfoNV& info, VkAccelerationStructureNV* structure) {
  auto copy = std::make_unique<Structure>();
  copy->info = info.info;
  copy->info.pNext = nullptr;
  if (info.info.pGeometries != nullptr) {
    copy->geometries.assign(info.info.pGeometries, info.info.pGeometries + info.info.geometryCount);
  }
  for (VkGeometryNV& g : copy->geometries) {
    g.pNext = nullptr;
    g.geometry.triangles.pNext = nullptr;
    g.geometry.aabbs.pNext = nullptr;
  }
  copy->info.geometryCount = static_cast<uint32_t>(copy->geometries.size());
  copy->info.pGeometries = copy->geometries.empty() ? nullptr : copy->geometries.data();
  copy->compacted_size = info.compactedSize;
  copy->handle = g_next_handle.fetch_add(1);
  // A non-dispatchable handle is 64 bits wide: the object's address.
  *structure = reinterpret_cast<VkAccelerationStructureNV>(copy.get());
  std::lock_guard<std::mutex> lock(lock_);
  structures_[*structure] = std::move(copy);
  return VK_SUCCESS;
}

void NvRayTracing::Destroy(VkAccelerationStructureNV structure) {
  std::lock_guard<std::mutex> lock(lock_);
  structures_.erase(structure);
}

const NvRayTracing::Structure* NvRayTracing::Find(VkAccelerationStructureNV structure) const {
  const auto it = structures_.find(structure);
  return it == structures_.end() ? nullptr : it->second.get();
}

void NvRayTracing::MemoryRequirements(const VkAccelerationStructureMemoryRequirementsInfoNV& info,
                                      VkMemoryRequirements2* requirements) const {
  uint64_t primitives = 0;
  VkDeviceSize compacted_size = 0;
  {
    std::lock_guard<std::mutex> lock(lock_);
    if (const Structure* s = Find(info.accelerationStructure)) {
      primitives = AsvalTestDriverNvPrimitives(s->info);
      compacted_size = s->compacted_size;
    }
  }
  VkMemoryRequirements& r = requirements->memoryRequirements;
  r.size = AsvalTestDriverNvMemorySize(info.type, primitives, compacted_size);
  r.alignment = kAsvalTestDriverNvMemoryAlignment;
  r.memoryTypeBits = memory_type_bits_;
  for (auto* s = static_cast<VkBaseOutStructure*>(requirements->pNext); s != nullptr; s = s->pNext) {
    if (s->sType == VK_STRUCTURE_TYPE_MEMORY_DEDICATED_REQUIREMENTS) {
      auto* dedicated = reinterpret_cast<VkMemoryDedicatedRequirements*>(s);
      dedicated->prefersDedicatedAllocation = VK_FALSE;
      dedicated->requiresDedicatedAllocation = VK_FALSE;
    }
  }
}

VkResult NvRayTracing::Bind(uint32_t count, const VkBindAccelerationStructureMemoryInfoNV* infos) {
  std::lock_guard<std::mutex> lock(lock_);
  for (uint32_t i = 0; i < count; ++i) {
    const auto it = structures_.find(infos[i].accelerationStructure);
    if (it == structures_.end()) continue;
    it->second->memory = infos[i].memory;
    it->second->offset = infos[i].memoryOffset;
  }
  return VK_SUCCESS;
}

VkResult NvRayTracing::Handle(VkAccelerationStructureNV structure, size_t size, void* data) const {
  uint64_t handle = 0;
  {
    std::lock_guard<std::mutex> lock(lock_);
    if (const Structure* s = Find(structure)) handle = s->handle;
  }
  std::memcpy(data, &handle, std::min(size, sizeof(handle)));
  return VK_SUCCESS;
}

namespace {

VKAPI_ATTR VkResult VKAPI_CALL CreateAccelerationStructureNV(VkDevice handle,
                                                             const VkAccelerationStructureCreateInfoNV* info,
                                                             const VkAllocationCallbacks*,
                                                             VkAccelerationStructureNV* structure) {
  return FindDevice(handle)->nv->Create(*info, structure);
}

VKAPI_ATTR void VKAPI_CALL DestroyAccelerationStructureNV(VkDevice handle, VkAccelerationStructureNV structure,
                                                          const VkAllocationCallbacks*) {
  FindDevice(handle)->nv->Destroy(structure);
}

VKAPI_ATTR void VKAPI_CALL GetAccelerationStructureMemoryRequirementsNV(
    VkDevice handle, const VkAccelerationStructureMemoryRequirementsInfoNV* info,
    VkMemoryRequirements2KHR* requirements) {
  FindDevice(handle)->nv->MemoryRequirements(*info, requirements);
}

VKAPI_ATTR VkResult VKAPI_CALL BindAccelerationStructureMemoryNV(VkDevice handle, uint32_t count,
                                                                 const VkBindAccelerationStructureMemoryInfoNV* infos) {
  return FindDevice(handle)->nv->Bind(count, infos);
}

VKAPI_ATTR VkResult VKAPI_CALL GetAccelerationStructureHandleNV(VkDevice handle, VkAccelerationStructureNV structure,
                                                                size_t size, void* data) {
  return FindDevice(handle)->nv->Handle(structure, size, data);
}

// Executed by no one (nv_ray_tracing.h): the command buffer below holds nothing of them.
VKAPI_ATTR void VKAPI_CALL CmdBuildAccelerationStructureNV(VkCommandBuffer, const VkAccelerationStructureInfoNV*,
                                                           VkBuffer, VkDeviceSize, VkBool32, VkAccelerationStructureNV,
                                                           VkAccelerationStructureNV, VkBuffer, VkDeviceSize) {}

VKAPI_ATTR void VKAPI_CALL CmdCopyAccelerationStructureNV(VkCommandBuffer, VkAccelerationStructureNV,
                                                          VkAccelerationStructureNV,
                                                          VkCopyAccelerationStructureModeKHR) {}

VKAPI_ATTR void VKAPI_CALL CmdWriteAccelerationStructuresPropertiesNV(VkCommandBuffer, uint32_t,
                                                                      const VkAccelerationStructureNV*, VkQueryType,
                                                                      VkQueryPool, uint32_t) {}

// The driver below has no NV query type: its KHR twin holds the same 64-bit values, and is reset and read alike.
VKAPI_ATTR VkResult VKAPI_CALL CreateQueryPool(VkDevice handle, const VkQueryPoolCreateInfo* info,
                                               const VkAllocationCallbacks* allocator, VkQueryPool* pool) {
  DeviceData* device = FindDevice(handle);
  VkQueryPoolCreateInfo below = *info;
  if (device->nv->enabled() && info->queryType == VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_NV) {
    below.queryType = VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR;
  }
  return device->vk.CreateQueryPool(handle, &below, allocator, pool);
}

}  // namespace

PFN_vkVoidFunction NvRayTracingFunction(const char* name) {
#define ASVAL_DRIVER_NV_HOOK(fn) \
  if (std::strcmp(name, "vk" #fn) == 0) return reinterpret_cast<PFN_vkVoidFunction>(&fn);
  ASVAL_DRIVER_NV_HOOK(CreateAccelerationStructureNV)
  ASVAL_DRIVER_NV_HOOK(DestroyAccelerationStructureNV)
  ASVAL_DRIVER_NV_HOOK(GetAccelerationStructureMemoryRequirementsNV)
  ASVAL_DRIVER_NV_HOOK(BindAccelerationStructureMemoryNV)
  ASVAL_DRIVER_NV_HOOK(GetAccelerationStructureHandleNV)
  ASVAL_DRIVER_NV_HOOK(CmdBuildAccelerationStructureNV)
  ASVAL_DRIVER_NV_HOOK(CmdCopyAccelerationStructureNV)
  ASVAL_DRIVER_NV_HOOK(CmdWriteAccelerationStructuresPropertiesNV)
  ASVAL_DRIVER_NV_HOOK(CreateQueryPool)
#undef ASVAL_DRIVER_NV_HOOK
  return nullptr;
}

}  // namespace asval_test_driver
