// The host copies and property writes of VK_KHR_acceleration_structure on the device below: the device command
// into a staging buffer (or from one), then the bytes copied to (or from) the host address.
#include <cstring>

#include "device_executor.h"
#include "driver_dispatch.h"
#include "host_commands.h"

namespace asval_test_driver {
namespace {

// Offset of the serialized size (a uint64_t, header included) in a serialized structure: after the driver's and
// the compatibility UUIDs.
constexpr size_t kSerializedSizeOffset = 2 * VK_UUID_SIZE;

// The device's answers to `type` for `count` structures, 64 bits each, `stride` bytes apart in `data`.
VkResult QueryProperties(DeviceData& device, uint32_t count, const VkAccelerationStructureKHR* structures,
                         VkQueryType type, size_t data_size, void* data, size_t stride) {
  VkQueryPoolCreateInfo info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  info.queryType = type;
  info.queryCount = count;
  VkQueryPool pool = VK_NULL_HANDLE;
  VkResult result = device.vk.CreateQueryPool(device.device, &info, nullptr, &pool);
  if (result != VK_SUCCESS) return result;
  result = device.executor->Run([&](VkCommandBuffer cb) {
    device.vk.CmdResetQueryPool(cb, pool, 0, count);
    device.vk.CmdWriteAccelerationStructuresPropertiesKHR(cb, count, structures, type, pool, 0);
  });
  if (result == VK_SUCCESS) {
    result = device.vk.GetQueryPoolResults(device.device, pool, 0, count, data_size, data, stride,
                                           VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT);
  }
  device.vk.DestroyQueryPool(device.device, pool, nullptr);
  return result;
}

}  // namespace

VkResult CopyOnHost(DeviceData& device, const VkCopyAccelerationStructureInfoKHR& info) {
  return device.executor->Run([&](VkCommandBuffer cb) { device.vk.CmdCopyAccelerationStructureKHR(cb, &info); });
}

VkResult CopyToMemoryOnHost(DeviceData& device, const VkCopyAccelerationStructureToMemoryInfoKHR& info) {
  uint64_t bytes = 0;
  VkResult result = QueryProperties(device, 1, &info.src, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR,
                                    sizeof(bytes), &bytes, sizeof(bytes));
  if (result != VK_SUCCESS) return result;
  StagingBuffer staging;
  result = device.executor->CreateStaging(bytes, &staging);
  if (result != VK_SUCCESS) return result;
  VkCopyAccelerationStructureToMemoryInfoKHR on_device = info;
  on_device.dst.deviceAddress = staging.address;
  result = device.executor->Run(
      [&](VkCommandBuffer cb) { device.vk.CmdCopyAccelerationStructureToMemoryKHR(cb, &on_device); });
  if (result == VK_SUCCESS) std::memcpy(info.dst.hostAddress, staging.mapped, bytes);
  device.executor->DestroyStaging(&staging);
  return result;
}

VkResult CopyFromMemoryOnHost(DeviceData& device, const VkCopyMemoryToAccelerationStructureInfoKHR& info) {
  uint64_t bytes = 0;
  std::memcpy(&bytes, static_cast<const unsigned char*>(info.src.hostAddress) + kSerializedSizeOffset, sizeof(bytes));
  // Bytes that are no serialized structure (an invalid call the layers above let through): the driver below would
  // read past them.
  if (bytes < kSerializedSizeOffset + 3 * sizeof(uint64_t)) return VK_ERROR_UNKNOWN;
  StagingBuffer staging;
  VkResult result = device.executor->CreateStaging(bytes, &staging);
  if (result != VK_SUCCESS) return result;
  std::memcpy(staging.mapped, info.src.hostAddress, bytes);
  VkCopyMemoryToAccelerationStructureInfoKHR on_device = info;
  on_device.src.deviceAddress = staging.address;
  result = device.executor->Run(
      [&](VkCommandBuffer cb) { device.vk.CmdCopyMemoryToAccelerationStructureKHR(cb, &on_device); });
  device.executor->DestroyStaging(&staging);
  return result;
}

VkResult WritePropertiesOnHost(DeviceData& device, uint32_t count, const VkAccelerationStructureKHR* structures,
                               VkQueryType type, size_t data_size, void* data, size_t stride) {
  return QueryProperties(device, count, structures, type, data_size, data, stride);
}

}  // namespace asval_test_driver
