#include "build_extension_helpers.h"

#include <cstring>

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
