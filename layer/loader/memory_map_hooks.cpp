// vkMapMemory / vkUnmapMemory: the layer remembers where the app's mappings are, so that host builds' host
// pointers that start inside one can be checked against its end (build_host.h). vkFreeMemory unmaps too
// (RecordFreeMemory).
#include "layer_data.h"
#include "state_tracker.h"
#include "vk_intercepts.h"

namespace asval::hooks {

VKAPI_ATTR VkResult VKAPI_CALL MapMemory(VkDevice device, VkDeviceMemory memory, VkDeviceSize offset, VkDeviceSize size,
                                         VkMemoryMapFlags flags, void** ppData) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.MapMemory(device, memory, offset, size, flags, ppData);
  if (result == VK_SUCCESS && ppData) RecordMapMemory(data->state, memory, offset, size, *ppData);
  return result;
}

VKAPI_ATTR void VKAPI_CALL UnmapMemory(VkDevice device, VkDeviceMemory memory) {
  DeviceData* data = GetDeviceData(device);
  RecordUnmapMemory(data->state, memory);
  data->dispatch.UnmapMemory(device, memory);
}

}  // namespace asval::hooks
