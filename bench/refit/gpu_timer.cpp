#include "gpu_timer.h"

#include "queue_family.h"

namespace refit {

GpuTimer::GpuTimer(vkkit::Device& device, VkPhysicalDevice gpu) : device_(device.handle()) {
  VkQueueFamilyProperties family{};
  DeviceQueueFamily(gpu, &family);
  const uint32_t bits = family.timestampValidBits;
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(gpu, &props);
  if (bits == 0 || props.limits.timestampPeriod <= 0.0f) return;
  valid_mask_ = bits >= 64 ? ~uint64_t{0} : (uint64_t{1} << bits) - 1;
  nanoseconds_per_tick_ = props.limits.timestampPeriod;
  VkQueryPoolCreateInfo info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  info.queryType = VK_QUERY_TYPE_TIMESTAMP;
  info.queryCount = 2;
  vkkit::Check(vkCreateQueryPool(device_, &info, nullptr, &pool_), "vkCreateQueryPool");
}

GpuTimer::~GpuTimer() {
  if (pool_) vkDestroyQueryPool(device_, pool_, nullptr);
}

void GpuTimer::RecordStart(VkCommandBuffer cb) const {
  if (!pool_) return;
  vkCmdResetQueryPool(cb, pool_, 0, 2);
  vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, pool_, 0);
}

void GpuTimer::RecordEnd(VkCommandBuffer cb) const {
  if (pool_) vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, pool_, 1);
}

double GpuTimer::ReadMilliseconds() const {
  if (!pool_) return 0.0;
  uint64_t ticks[2] = {0, 0};
  vkkit::Check(vkGetQueryPoolResults(device_, pool_, 0, 2, sizeof(ticks), ticks, sizeof(uint64_t),
                                     VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
               "vkGetQueryPoolResults");
  const uint64_t elapsed = ((ticks[1] & valid_mask_) - (ticks[0] & valid_mask_)) & valid_mask_;
  return static_cast<double>(elapsed) * nanoseconds_per_tick_ * 1e-6;
}

}  // namespace refit
