#include "build_extension_helpers.h"

#include <cstring>

#include "history_helpers.h"
#include "memory_placement_helpers.h"

namespace asval_test {

MotionBlurDevice::MotionBlurDevice() {
  options.extensions.push_back(VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME);
  options.extensions.push_back(VK_NV_RAY_TRACING_MOTION_BLUR_EXTENSION_NAME);
  features.rayTracingMotionBlur = VK_TRUE;
  options.features = &features;
}

OpacityMicromapDevice::OpacityMicromapDevice() {
  options.extensions.push_back(VK_EXT_OPACITY_MICROMAP_EXTENSION_NAME);
  features.micromap = VK_TRUE;
  options.features = &features;
}

MotionStructure::MotionStructure(vkkit::Device& device, bool motion) : device_(device) {
  storage_ = device.CreateBuffer(1 << 16, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR);
  VkAccelerationStructureMotionInfoNV motion_info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_MOTION_INFO_NV};
  VkAccelerationStructureCreateInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
  info.pNext = motion ? &motion_info : nullptr;
  info.createFlags = motion ? VK_ACCELERATION_STRUCTURE_CREATE_MOTION_BIT_NV : 0;
  info.buffer = storage_.buffer;
  info.size = storage_.size;
  info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  vkkit::Check(device.CreateAccelerationStructureKHR(device.handle(), &info, nullptr, &handle_),
               "vkCreateAccelerationStructureKHR");
}

MotionStructure::~MotionStructure() {
  device_.DestroyAccelerationStructureKHR(device_.handle(), handle_, nullptr);
  device_.Destroy(storage_);
}

MotionRefit::MotionRefit(vkkit::Device& device, bool motion)
    : device_(device), motion_(motion), structure_(device, motion) {
  for (vkkit::Buffer* b : {&at_0_, &at_1_}) {
    *b = device.CreateBuffer(256, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
  }
  scratch_ = device.CreateBuffer(1 << 20, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  Write(at_0_, 0.0f);
  Write(at_1_, 0.0f);
}

MotionRefit::~MotionRefit() {
  for (vkkit::Buffer* b : {&at_0_, &at_1_, &scratch_}) device_.Destroy(*b);
}

void MotionRefit::Write(vkkit::Buffer& buffer, float dx) {
  float v[18];
  const float corner[3][2] = {{0, 0}, {1, 0}, {0, 1}};
  for (int k = 0; k < 6; ++k) {
    v[3 * k + 0] = corner[k % 3][0] + dx;
    v[3 * k + 1] = corner[k % 3][1];
    v[3 * k + 2] = static_cast<float>(k / 3);
  }
  std::memcpy(buffer.mapped, v, sizeof(v));
}

void MotionRefit::NanAtTime1(uint32_t t) {
  const uint32_t nan = 0x7fc00000u;
  std::memcpy(static_cast<char*>(at_1_.mapped) + 36 * t, &nan, sizeof(nan));
}

VkAccelerationStructureBuildGeometryInfoKHR MotionRefit::Info(
    bool update, bool host, VkAccelerationStructureGeometryMotionTrianglesDataNV& time_1,
    VkAccelerationStructureGeometryKHR& geometry) {
  time_1 = VkAccelerationStructureGeometryMotionTrianglesDataNV{
      VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_MOTION_TRIANGLES_DATA_NV};
  geometry = VkAccelerationStructureGeometryKHR{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  geometry.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
  geometry.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
  VkAccelerationStructureGeometryTrianglesDataKHR& t = geometry.geometry.triangles;
  t.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
  t.pNext = &time_1;  // chained either way: read only by a motion build
  t.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
  t.vertexStride = 12;
  t.maxVertex = 5;
  t.indexType = VK_INDEX_TYPE_NONE_KHR;
  VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  if (host) {
    time_1.vertexData.hostAddress = at_1_.mapped;
    t.vertexData.hostAddress = at_0_.mapped;
    info.scratchData.hostAddress = host_scratch_.data();
  } else {
    time_1.vertexData.deviceAddress = at_1_.address;
    t.vertexData.deviceAddress = at_0_.address;
    info.scratchData.deviceAddress = scratch_.address;
  }
  info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  info.flags = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR |
               (motion_ ? VK_BUILD_ACCELERATION_STRUCTURE_MOTION_BIT_NV : 0);
  info.mode = update ? VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR : VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  info.srcAccelerationStructure = update ? structure_.handle() : VK_NULL_HANDLE;
  info.dstAccelerationStructure = structure_.handle();
  info.geometryCount = 1;
  info.pGeometries = &geometry;
  return info;
}

VkResult MotionRefit::Run(bool update) {
  VkAccelerationStructureGeometryMotionTrianglesDataNV time_1;
  VkAccelerationStructureGeometryKHR geometry;
  const VkAccelerationStructureBuildGeometryInfoKHR info = Info(update, false, time_1, geometry);
  const VkAccelerationStructureBuildRangeInfoKHR range{2, 0, 0, 0};
  const VkAccelerationStructureBuildRangeInfoKHR* ranges = &range;
  Commands commands(device_);
  VkCommandBuffer cb = commands.Begin();
  device_.CmdBuildAccelerationStructuresKHR(cb, 1, &info, &ranges);
  commands.End(cb);
  return commands.Submit(cb);
}

VkResult MotionRefit::RunOnHost(bool update) {
  VkAccelerationStructureGeometryMotionTrianglesDataNV time_1;
  VkAccelerationStructureGeometryKHR geometry;
  const VkAccelerationStructureBuildGeometryInfoKHR info = Info(update, true, time_1, geometry);
  const VkAccelerationStructureBuildRangeInfoKHR range{2, 0, 0, 0};
  return CallHostBuild(device_, {info}, {&range});
}

Micromap::Micromap(vkkit::Device& device) : device_(device) {
  storage_ = device.CreateBuffer(4096, VK_BUFFER_USAGE_MICROMAP_STORAGE_BIT_EXT);
  auto create = reinterpret_cast<PFN_vkCreateMicromapEXT>(vkGetDeviceProcAddr(device.handle(), "vkCreateMicromapEXT"));
  destroy_ = reinterpret_cast<PFN_vkDestroyMicromapEXT>(vkGetDeviceProcAddr(device.handle(), "vkDestroyMicromapEXT"));
  VkMicromapCreateInfoEXT info{VK_STRUCTURE_TYPE_MICROMAP_CREATE_INFO_EXT};
  info.buffer = storage_.buffer;
  info.size = storage_.size;
  info.type = VK_MICROMAP_TYPE_OPACITY_MICROMAP_EXT;
  vkkit::Check(create(device.handle(), &info, nullptr, &handle_), "vkCreateMicromapEXT");
}

Micromap::~Micromap() {
  destroy_(device_.handle(), handle_, nullptr);
  device_.Destroy(storage_);
}

vkkit::Buffer SpecialIndexBuffer(vkkit::Device& device) {
  vkkit::Buffer buffer = device.CreateBuffer(256, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
  const uint32_t opaque = static_cast<uint32_t>(VK_OPACITY_MICROMAP_SPECIAL_INDEX_FULLY_OPAQUE_EXT);
  std::memcpy(buffer.mapped, &opaque, sizeof(opaque));
  return buffer;
}

VkAccelerationStructureTrianglesOpacityMicromapEXT OpacityFromSpecialIndices(const vkkit::Buffer& indices,
                                                                             const Micromap& micromap,
                                                                             VkDeviceSize stride) {
  VkAccelerationStructureTrianglesOpacityMicromapEXT m{
      VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_TRIANGLES_OPACITY_MICROMAP_EXT};
  m.indexType = VK_INDEX_TYPE_UINT32;
  m.indexBuffer.deviceAddress = indices.address;
  m.indexStride = stride;
  m.micromap = micromap.handle();
  return m;
}

}  // namespace asval_test
