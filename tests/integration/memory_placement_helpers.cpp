#include "memory_placement_helpers.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace asval_test {

namespace {

constexpr VkBufferUsageFlags kAnyUsage =
    VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR |
    VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
    VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;

VkBuffer NewBuffer(VkDevice device, VkDeviceSize size, VkBufferUsageFlags usage) {
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = size;
  info.usage = usage | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VkBuffer buffer = VK_NULL_HANDLE;
  vkkit::Check(vkCreateBuffer(device, &info, nullptr, &buffer), "vkCreateBuffer");
  return buffer;
}

}  // namespace

SharedMemory::SharedMemory(vkkit::Device& device, VkDeviceSize size) : device_(device) {
  VkBuffer probe = NewBuffer(device.handle(), 256, kAnyUsage);
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device.handle(), probe, &req);
  vkDestroyBuffer(device.handle(), probe, nullptr);
  // Host-visible and coherent, so that tests can write inputs through one mapping (lavapipe has one such
  // type; discrete GPUs have several types and map only these).
  const uint32_t type = device.FindMemoryType(
      req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
  flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &flags};
  alloc.allocationSize = size;
  alloc.memoryTypeIndex = type;
  vkkit::Check(vkAllocateMemory(device.handle(), &alloc, nullptr, &memory_), "vkAllocateMemory");
  vkkit::Check(vkMapMemory(device.handle(), memory_, 0, VK_WHOLE_SIZE, 0, &mapped_), "vkMapMemory");
}

SharedMemory::~SharedMemory() {
  for (VkAccelerationStructureKHR as : structures_) device_.DestroyAccelerationStructureKHR(device_.handle(), as, nullptr);
  for (VkBuffer buffer : buffers_) vkDestroyBuffer(device_.handle(), buffer, nullptr);
  vkFreeMemory(device_.handle(), memory_, nullptr);
}

vkkit::Buffer SharedMemory::Bind(VkDeviceSize offset, VkDeviceSize size, VkBufferUsageFlags usage) {
  vkkit::Buffer b;
  b.size = size;
  b.buffer = NewBuffer(device_.handle(), size, usage);
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device_.handle(), b.buffer, &req);
  if (offset % req.alignment != 0) throw std::runtime_error("SharedMemory: offset breaks the buffer's alignment");
  vkkit::Check(vkBindBufferMemory(device_.handle(), b.buffer, memory_, offset), "vkBindBufferMemory");
  const VkBufferDeviceAddressInfo address{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO, nullptr, b.buffer};
  b.address = vkGetBufferDeviceAddress(device_.handle(), &address);
  b.mapped = static_cast<char*>(mapped_) + offset;
  buffers_.push_back(b.buffer);
  return b;
}

VkAccelerationStructureKHR SharedMemory::Structure(const vkkit::Buffer& buffer, VkDeviceSize offset, VkDeviceSize size,
                                                   VkAccelerationStructureTypeKHR type) {
  VkAccelerationStructureCreateInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
  info.buffer = buffer.buffer;
  info.offset = offset;
  info.size = size;
  info.type = type;
  VkAccelerationStructureKHR as = VK_NULL_HANDLE;
  vkkit::Check(device_.CreateAccelerationStructureKHR(device_.handle(), &info, nullptr, &as),
               "vkCreateAccelerationStructureKHR");
  structures_.push_back(as);
  return as;
}

void SharedMemory::DestroyBuffer(vkkit::Buffer& buffer) {
  buffers_.erase(std::remove(buffers_.begin(), buffers_.end(), buffer.buffer), buffers_.end());
  vkDestroyBuffer(device_.handle(), buffer.buffer, nullptr);
  buffer = vkkit::Buffer{};
}

void SharedMemory::DestroyStructure(VkAccelerationStructureKHR structure) {
  structures_.erase(std::remove(structures_.begin(), structures_.end(), structure), structures_.end());
  device_.DestroyAccelerationStructureKHR(device_.handle(), structure, nullptr);
}

VkAccelerationStructureBuildSizesInfoKHR DriverSizes(vkkit::Device& device,
                                                     const VkAccelerationStructureBuildGeometryInfoKHR& info,
                                                     const std::vector<uint32_t>& counts) {
  VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
  device.GetAccelerationStructureBuildSizesKHR(device.handle(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &info,
                                               counts.data(), &sizes);
  return sizes;
}

void RecordIndirect(vkkit::Device& device, const std::vector<VkAccelerationStructureBuildGeometryInfoKHR>& infos,
                    const std::vector<VkDeviceAddress>& addresses, const std::vector<uint32_t>& strides,
                    const std::vector<std::vector<uint32_t>>& max_counts) {
  auto indirect = reinterpret_cast<PFN_vkCmdBuildAccelerationStructuresIndirectKHR>(
      vkGetDeviceProcAddr(device.handle(), "vkCmdBuildAccelerationStructuresIndirectKHR"));
  if (!indirect) throw std::runtime_error("vkCmdBuildAccelerationStructuresIndirectKHR is not available");
  std::vector<const uint32_t*> max_count_pointers;
  for (const std::vector<uint32_t>& counts : max_counts) max_count_pointers.push_back(counts.data());
  device.OneShot(
      [&](VkCommandBuffer cb) {
        indirect(cb, static_cast<uint32_t>(infos.size()), infos.data(), addresses.data(), strides.data(),
                 max_count_pointers.data());
      },
      /*submit=*/false);
}

VkResult CallHostBuild(vkkit::Device& device, const std::vector<VkAccelerationStructureBuildGeometryInfoKHR>& infos,
                       const std::vector<const VkAccelerationStructureBuildRangeInfoKHR*>& ranges,
                       VkDeferredOperationKHR deferred) {
  auto host = reinterpret_cast<PFN_vkBuildAccelerationStructuresKHR>(
      vkGetDeviceProcAddr(device.handle(), "vkBuildAccelerationStructuresKHR"));
  if (!host) throw std::runtime_error("vkBuildAccelerationStructuresKHR is not available");
  return host(device.handle(), deferred, static_cast<uint32_t>(infos.size()), infos.data(), ranges.data());
}

void IssueWithRealRanges(vkkit::Device& device, Command command,
                         const std::vector<VkAccelerationStructureBuildGeometryInfoKHR>& infos,
                         const std::vector<const VkAccelerationStructureBuildRangeInfoKHR*>& ranges) {
  if (command != Command::kIndirect) {
    Issue(device, command, infos, ranges);
    return;
  }
  VkDeviceSize total = 0;
  for (const auto& info : infos) total += info.geometryCount;
  vkkit::Buffer buffer = device.CreateBuffer(std::max<VkDeviceSize>(16 * total, 16), VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  std::vector<VkDeviceAddress> addresses;
  std::vector<uint32_t> strides;
  std::vector<std::vector<uint32_t>> max_counts;
  VkDeviceSize offset = 0;
  for (size_t i = 0; i < infos.size(); ++i) {
    addresses.push_back(buffer.address + offset);
    strides.push_back(16);
    max_counts.emplace_back();
    for (uint32_t j = 0; j < infos[i].geometryCount; ++j) {
      std::memcpy(static_cast<char*>(buffer.mapped) + offset, &ranges[i][j], 16);
      max_counts.back().push_back(ranges[i][j].primitiveCount);
      offset += 16;
    }
  }
  RecordIndirect(device, infos, addresses, strides, max_counts);
  device.Destroy(buffer);
}

void BuildBarrier(VkCommandBuffer cb) {
  VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  barrier.srcAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;
  barrier.dstAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR | VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                       VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, 0, 1, &barrier, 0, nullptr, 0, nullptr);
}

}  // namespace asval_test
