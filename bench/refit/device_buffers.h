#pragma once
// Device-local buffers for the refit benchmark. vkkit's buffers are host-visible (what tests want); on a
// discrete GPU that would put the vertices, indices, scratch and structures the builds touch every frame in
// host memory across the bus, and the GPU time would measure the bus. On lavapipe every type is both.
#include <vulkan/vulkan.h>

#include "vkkit.h"

namespace refit {

// Device-local, with a device address; not mapped. Release with vkkit::Device::Destroy.
vkkit::Buffer CreateDeviceLocalBuffer(vkkit::Device& device, VkDeviceSize size, VkBufferUsageFlags usage);
// A device-local buffer holding `bytes`, copied through a host-visible staging buffer (TRANSFER_DST is added).
vkkit::Buffer UploadToDevice(vkkit::Device& device, const void* bytes, VkDeviceSize size, VkBufferUsageFlags usage);

}  // namespace refit
