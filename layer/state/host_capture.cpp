#include "host_capture.h"

#include <cstring>
#include <new>

#include "capture_plan.h"
#include "failure_injection.h"

namespace asval {

namespace {

// Slabs on the heap: a host build's capture is read on the calling thread, at once or when its deferred operation
// completes, never by the device.
class HeapSlabOwner final : public CaptureSlabOwner {
 public:
  bool Take(VkDeviceSize bytes, CaptureSlab* slab) override {
    auto* memory = new (std::nothrow) uint8_t[bytes];
    if (!memory) return false;
    slab->mapped = memory;
    slab->size = bytes;
    return true;
  }
  void Return(const CaptureSlab& slab) override { delete[] slab.mapped; }
};

}  // namespace

namespace {

// `uncounted`: the first info not yet counted as captured or not (an allocation failure counts those from there).
HostCapture CaptureOrThrow(uint32_t info_count, const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                           const VkAccelerationStructureBuildRangeInfoKHR* const* ranges, VkDeviceSize budget_bytes,
                           CaptureCounters& counters, uint32_t* uncounted) {
  HostCapture capture;
  InjectBadAlloc(FailSite::kCaptureRecord);
  std::vector<CaptureSource> sources;
  std::vector<CapturedGeometry> planned;
  for (uint32_t i = 0; i < info_count; ++i) {
    const VkAccelerationStructureBuildGeometryInfoKHR& info = infos[i];
    if (!ActivityNeededForUpdates(info)) continue;
    if (!capture.log) {
      capture.log = std::make_shared<CaptureLog>(std::make_shared<HeapSlabOwner>());
      capture.captured.assign(info_count, 0);
    }
    CaptureLog& log = *capture.log;
    CapturedInfo entry;
    entry.geometry_count = info.geometryCount;
    entry.element = i;
    planned.assign(info.geometryCount, CapturedGeometry{});
    sources.clear();
    // Motion (VK_NV_ray_tracing_motion_blur): triangles are read at both times; motion instances have other records,
    // not captured yet.
    const bool motion = (info.flags & VK_BUILD_ACCELERATION_STRUCTURE_MOTION_BIT_NV) != 0;
    const bool motion_instances = motion && info.type != VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    CaptureSkip why = motion_instances ? CaptureSkip::kGeometryNotCaptured : CaptureSkip::kNullInput;
    entry.complete = ranges[i] && (info.pGeometries || info.ppGeometries) && !motion_instances;
    for (uint32_t j = 0; j < info.geometryCount && entry.complete; ++j) {
      const VkAccelerationStructureGeometryKHR* g = info.pGeometries ? &info.pGeometries[j] : info.ppGeometries[j];
      entry.complete = g && PlanCapturedGeometry(*g, ranges[i][j], true, &planned[j], sources, &why, motion);
    }
    VkDeviceSize total = 0;
    for (const CaptureSource& s : sources) total = SaturatingAddBytes(total, s.size);
    if (entry.complete && SaturatingAddBytes(log.bytes_captured, total) > budget_bytes) {
      entry.complete = false;
      why = CaptureSkip::kOverBudget;
    }
    for (const CaptureSource& s : sources) {
      if (!entry.complete) break;
      if (!log.Reserve(s.size, s.into)) {  // the heap block could not be had
        counters.failures.capture_memory_failures.fetch_add(1, std::memory_order_relaxed);
        why = CaptureSkip::kCaptureMemoryFailed;
        entry.complete = false;
        break;
      }
      // The slab is this log's own heap memory (HeapSlabOwner), written here only, before anyone reads it.
      std::memcpy(const_cast<uint8_t*>(log.Bytes(*s.into)), reinterpret_cast<const void*>(s.address), s.size);
    }
    if (entry.complete) {
      counters.infos_captured.fetch_add(1, std::memory_order_relaxed);
      counters.bytes_captured.fetch_add(total, std::memory_order_relaxed);
    } else {
      counters.NotCaptured(why);
    }
    *uncounted = i + 1;
    capture.captured[i] = log.AddInfo(entry, planned.data(), nullptr, total);
  }
  return capture;
}

}  // namespace

HostCapture CaptureHostBuildInputs(uint32_t info_count, const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                                   const VkAccelerationStructureBuildRangeInfoKHR* const* ranges,
                                   VkDeviceSize budget_bytes, CaptureCounters& counters) {
  if (!infos || !ranges) return HostCapture{};
  uint32_t uncounted = 0;
  try {
    return CaptureOrThrow(info_count, infos, ranges, budget_bytes, counters, &uncounted);
  } catch (const std::bad_alloc&) {
    // Nothing captured: the call's updates are not judged on their inputs, and its builds leave no activity
    // (skipped and counted where a later update needs it). The infos counted before the failure stay counted; those
    // from the failure on are counted as not captured for it.
    counters.failures.allocation_failures.fetch_add(1, std::memory_order_relaxed);
    counters.failures.capture_commands_dropped.fetch_add(1, std::memory_order_relaxed);
    for (uint32_t i = uncounted; i < info_count; ++i) {
      if (ActivityNeededForUpdates(infos[i])) counters.NotCaptured(CaptureSkip::kAllocationFailed);
    }
    return HostCapture{};
  }
}

}  // namespace asval
