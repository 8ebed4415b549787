// vkMapMemory / vkUnmapMemory: the layer remembers where the app's mappings are, so that host builds' host
// pointers that start inside one can be checked against its end (build_host.h). vkFreeMemory unmaps too
// (RecordFreeMemory).
#include "layer_data.h"
#include "vk_intercepts.h"

namespace asval::hooks {

VKAPI_ATTR VkResult VKAPI_CALL MapMemory(VkDevice device, VkDeviceMemory memory, VkDeviceSize offset, VkDeviceSize size,
                                         VkMemoryMapFlags flags, void** ppData) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.MapMemory(device, memory, offset, size, flags, ppData);
  if (result != VK_SUCCESS || !ppData) return result;
  VkDeviceSize bytes = size;
  if (size == VK_WHOLE_SIZE) {
    const std::optional<std::shared_ptr<const MemoryState>> record = data->state.memories.find(memory);
    if (!record || !*record || (*record)->size < offset) return result;  // extent unknown: not recorded
    bytes = (*record)->size - offset;
  }
  data->state.host_mappings.Map(memory, offset, bytes, *ppData);
  return result;
}

VKAPI_ATTR void VKAPI_CALL UnmapMemory(VkDevice device, VkDeviceMemory memory) {
  DeviceData* data = GetDeviceData(device);
  data->state.host_mappings.Unmap(memory);
  data->dispatch.UnmapMemory(device, memory);
}

}  // namespace asval::hooks
