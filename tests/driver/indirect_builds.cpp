#include "indirect_builds.h"

#include <algorithm>
#include <cstring>

#include "device_buffers.h"
#include "device_executor.h"
#include "driver_dispatch.h"
#include "host_inputs.h"

namespace asval_test_driver {

IndirectBuilds::IndirectBuilds(DeviceData& device) : device_(device) {}

IndirectBuilds::~IndirectBuilds() {
  if (pool_ != VK_NULL_HANDLE) device_.vk.DestroyCommandPool(device_.device, pool_, nullptr);
}

void IndirectBuilds::Begin(VkCommandBuffer command_buffer) {
  std::lock_guard<std::mutex> lock(lock_);
  sites_.erase(command_buffer);  // its secondaries stay in the pool, freed with it
}

void IndirectBuilds::Record(VkCommandBuffer command_buffer, uint32_t info_count,
                            const VkAccelerationStructureBuildGeometryInfoKHR* infos, const VkDeviceAddress* addresses,
                            const uint32_t* strides, const uint32_t* const* max_counts) {
  Site site;
  for (uint32_t i = 0; i < info_count; ++i) {
    Build build;
    build.info = infos[i];
    build.info.pNext = nullptr;
    for (uint32_t g = 0; g < infos[i].geometryCount; ++g) {
      build.geometries.push_back(infos[i].pGeometries != nullptr ? infos[i].pGeometries[g] : *infos[i].ppGeometries[g]);
      build.geometries.back().pNext = nullptr;
      build.max_counts.push_back(max_counts[i][g]);
    }
    build.address = addresses[i];
    build.stride = strides[i];
    site.builds.push_back(std::move(build));
  }
  std::lock_guard<std::mutex> lock(lock_);
  if (pool_ == VK_NULL_HANDLE) {
    VkCommandPoolCreateInfo pool{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pool.queueFamilyIndex = device_.queue_family;
    if (device_.vk.CreateCommandPool(device_.device, &pool, nullptr, &pool_) != VK_SUCCESS) return;
  }
  VkCommandBufferAllocateInfo allocate{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  allocate.commandPool = pool_;
  allocate.level = VK_COMMAND_BUFFER_LEVEL_SECONDARY;
  allocate.commandBufferCount = 1;
  if (device_.vk.AllocateCommandBuffers(device_.device, &allocate, &site.secondary) != VK_SUCCESS) return;
  // Empty until a submission records it: a build whose ranges cannot be read builds nothing.
  VkResult result = RecordSecondary(site, {});
  if (result != VK_SUCCESS) return;
  device_.vk.CmdExecuteCommands(command_buffer, 1, &site.secondary);
  sites_[command_buffer].push_back(std::move(site));
}

VkResult IndirectBuilds::RecordSecondary(const Site& site,
                                         std::vector<std::vector<VkAccelerationStructureBuildRangeInfoKHR>> ranges) {
  const DeviceFunctions& vk = device_.vk;
  vk.ResetCommandBuffer(site.secondary, 0);
  VkCommandBufferInheritanceInfo inheritance{VK_STRUCTURE_TYPE_COMMAND_BUFFER_INHERITANCE_INFO};
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.pInheritanceInfo = &inheritance;
  VkResult result = vk.BeginCommandBuffer(site.secondary, &begin);
  if (result != VK_SUCCESS) return result;
  if (!ranges.empty()) {
    std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos;
    std::vector<std::vector<VkAccelerationStructureGeometryKHR>> geometries;
    std::vector<const VkAccelerationStructureBuildRangeInfoKHR*> range_pointers;
    for (size_t i = 0; i < site.builds.size(); ++i) {
      geometries.push_back(site.builds[i].geometries);
      infos.push_back(site.builds[i].info);
      range_pointers.push_back(ranges[i].data());
    }
    for (size_t i = 0; i < infos.size(); ++i) {
      for (size_t g = 0; g < geometries[i].size(); ++g) FoldFirstVertex(geometries[i][g], ranges[i][g]);
      infos[i].pGeometries = geometries[i].data();
      infos[i].ppGeometries = nullptr;
    }
    vk.CmdBuildAccelerationStructuresKHR(site.secondary, static_cast<uint32_t>(infos.size()), infos.data(),
                                         range_pointers.data());
  }
  return vk.EndCommandBuffer(site.secondary);
}

VkResult IndirectBuilds::Prepare(VkQueue queue, const std::vector<VkCommandBuffer>& command_buffers) {
  std::lock_guard<std::mutex> lock(lock_);
  std::vector<const Site*> sites;
  for (VkCommandBuffer cb : command_buffers) {
    const auto it = sites_.find(cb);
    if (it == sites_.end()) continue;
    for (const Site& site : it->second) sites.push_back(&site);
  }
  if (sites.empty()) return VK_SUCCESS;
  // Earlier submissions have written what they write, and no secondary is still executing.
  VkResult result = device_.vk.QueueWaitIdle(queue);
  if (result != VK_SUCCESS) return result;

  // Every info's range infos, copied by the driver below into one staging buffer.
  struct Read {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceSize offset = 0;
    VkDeviceSize bytes = 0;
    VkDeviceSize at = 0;
    bool found = false;
  };
  std::vector<Read> reads;
  VkDeviceSize total = 0;
  for (const Site* site : sites) {
    for (const Build& build : site->builds) {
      Read read;
      const size_t count = build.geometries.size();
      read.bytes =
          count == 0 ? 0 : uint64_t{build.stride} * (count - 1) + sizeof(VkAccelerationStructureBuildRangeInfoKHR);
      read.found = read.bytes != 0 && device_.buffers->Find(build.address, read.bytes, &read.buffer, &read.offset);
      read.at = total;
      total += (read.bytes + 15) / 16 * 16;
      reads.push_back(read);
    }
  }
  StagingBuffer staging;
  result = device_.executor->CreateStaging(total, &staging);
  if (result != VK_SUCCESS) return result;
  result = device_.executor->Run(
      [&](VkCommandBuffer cb) {
        for (const Read& read : reads) {
          if (!read.found) continue;
          const VkBufferCopy region{read.offset, read.at, read.bytes};
          device_.vk.CmdCopyBuffer(cb, read.buffer, staging.buffer, 1, &region);
        }
      },
      /*queue_locked=*/true);

  size_t next_read = 0;
  for (const Site* site : sites) {
    std::vector<std::vector<VkAccelerationStructureBuildRangeInfoKHR>> ranges;
    bool readable = result == VK_SUCCESS;
    for (const Build& build : site->builds) {
      const Read& read = reads[next_read++];
      readable = readable && (read.found || build.geometries.empty());
      std::vector<VkAccelerationStructureBuildRangeInfoKHR> info_ranges(build.geometries.size());
      for (size_t g = 0; g < info_ranges.size() && read.found; ++g) {
        std::memcpy(&info_ranges[g], staging.mapped + read.at + g * build.stride, sizeof(info_ranges[g]));
        // The driver protects itself: a count above the recorded maximum (invalid) is built as the maximum.
        info_ranges[g].primitiveCount = std::min(info_ranges[g].primitiveCount, build.max_counts[g]);
      }
      ranges.push_back(std::move(info_ranges));
    }
    const VkResult recorded = RecordSecondary(*site, readable ? std::move(ranges) : decltype(ranges){});
    if (result == VK_SUCCESS) result = recorded;
  }
  device_.executor->DestroyStaging(&staging);
  return result;
}

}  // namespace asval_test_driver
