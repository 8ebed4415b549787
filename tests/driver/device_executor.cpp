#include "device_executor.h"

#include "driver_dispatch.h"

namespace asval_test_driver {

DeviceExecutor::DeviceExecutor(DeviceData& device) : device_(device) {}

DeviceExecutor::~DeviceExecutor() {
  const DeviceFunctions& vk = device_.vk;
  if (fence_ != VK_NULL_HANDLE) vk.DestroyFence(device_.device, fence_, nullptr);
  if (pool_ != VK_NULL_HANDLE) vk.DestroyCommandPool(device_.device, pool_, nullptr);
}

VkResult DeviceExecutor::CreateStaging(VkDeviceSize bytes, StagingBuffer* out) {
  const DeviceFunctions& vk = device_.vk;
  *out = {};
  out->size = bytes < 256 ? 256 : bytes;
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = out->size;
  info.usage = VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
               VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
               VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  VkResult result = vk.CreateBuffer(device_.device, &info, nullptr, &out->buffer);
  if (result != VK_SUCCESS) return result;
  VkMemoryRequirements needs{};
  vk.GetBufferMemoryRequirements(device_.device, out->buffer, &needs);
  const VkMemoryPropertyFlags wanted = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  uint32_t type = UINT32_MAX;
  for (uint32_t i = 0; i < device_.memory.memoryTypeCount && type == UINT32_MAX; ++i) {
    if ((needs.memoryTypeBits & (1u << i)) && (device_.memory.memoryTypes[i].propertyFlags & wanted) == wanted)
      type = i;
  }
  if (type == UINT32_MAX) {
    DestroyStaging(out);
    return VK_ERROR_OUT_OF_DEVICE_MEMORY;
  }
  VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
  flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  VkMemoryAllocateInfo allocate{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &flags};
  allocate.allocationSize = needs.size;
  allocate.memoryTypeIndex = type;
  result = vk.AllocateMemory(device_.device, &allocate, nullptr, &out->memory);
  if (result == VK_SUCCESS) result = vk.BindBufferMemory(device_.device, out->buffer, out->memory, 0);
  void* mapped = nullptr;
  if (result == VK_SUCCESS) result = vk.MapMemory(device_.device, out->memory, 0, VK_WHOLE_SIZE, 0, &mapped);
  if (result != VK_SUCCESS) {
    DestroyStaging(out);
    return result;
  }
  out->mapped = static_cast<unsigned char*>(mapped);
  VkBufferDeviceAddressInfo address{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
  address.buffer = out->buffer;
  out->address = vk.GetBufferDeviceAddress(device_.device, &address);
  return VK_SUCCESS;
}

void DeviceExecutor::DestroyStaging(StagingBuffer* buffer) {
  const DeviceFunctions& vk = device_.vk;
  if (buffer->buffer != VK_NULL_HANDLE) vk.DestroyBuffer(device_.device, buffer->buffer, nullptr);
  if (buffer->memory != VK_NULL_HANDLE) vk.FreeMemory(device_.device, buffer->memory, nullptr);
  *buffer = {};
}

VkResult DeviceExecutor::Prepare() {
  if (fence_ != VK_NULL_HANDLE) return VK_SUCCESS;
  const DeviceFunctions& vk = device_.vk;
  vk.GetDeviceQueue(device_.device, device_.queue_family, 0, &queue_);
  VkCommandPoolCreateInfo pool{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
  pool.queueFamilyIndex = device_.queue_family;
  VkResult result = vk.CreateCommandPool(device_.device, &pool, nullptr, &pool_);
  if (result != VK_SUCCESS) return result;
  VkCommandBufferAllocateInfo allocate{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  allocate.commandPool = pool_;
  allocate.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  allocate.commandBufferCount = 1;
  result = vk.AllocateCommandBuffers(device_.device, &allocate, &command_buffer_);
  if (result != VK_SUCCESS) return result;
  VkFenceCreateInfo fence{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  return vk.CreateFence(device_.device, &fence, nullptr, &fence_);
}

VkResult DeviceExecutor::Run(const std::function<void(VkCommandBuffer)>& record, bool queue_locked) {
  std::lock_guard<std::mutex> lock(lock_);
  VkResult result = Prepare();
  if (result != VK_SUCCESS) return result;
  const DeviceFunctions& vk = device_.vk;
  vk.ResetCommandPool(device_.device, pool_, 0);
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  result = vk.BeginCommandBuffer(command_buffer_, &begin);
  if (result != VK_SUCCESS) return result;
  // What the host wrote before the call is visible to the device (coherent memory, the submission's own
  // host-write guarantee); what the commands write is made visible to the host after them.
  record(command_buffer_);
  VkMemoryBarrier to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  to_host.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
  to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vk.CmdPipelineBarrier(command_buffer_, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &to_host,
                        0, nullptr, 0, nullptr);
  result = vk.EndCommandBuffer(command_buffer_);
  if (result != VK_SUCCESS) return result;
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &command_buffer_;
  if (queue_locked) {
    result = vk.QueueSubmit(queue_, 1, &submit, fence_);
  } else {
    std::lock_guard<std::mutex> queue(device_.queue_lock);
    result = vk.QueueSubmit(queue_, 1, &submit, fence_);
  }
  if (result != VK_SUCCESS) return result;
  result = vk.WaitForFences(device_.device, 1, &fence_, VK_TRUE, UINT64_MAX);
  vk.ResetFences(device_.device, 1, &fence_);
  return result;
}

}  // namespace asval_test_driver
