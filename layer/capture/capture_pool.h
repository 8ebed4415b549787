#pragma once
// Layer-owned host-visible memory that device builds' inputs are copied into (execution-time capture, issue 12):
// slabs of one VkBuffer each, bound to their own HOST_VISIBLE | HOST_COHERENT memory and mapped for life. A
// recording takes slabs as it captures (CaptureLog) and gives them back when nothing reads it any more; they are
// reused. Every call goes to the next element of the chain, never to the layer's own hooks.
#include <vulkan/vulkan.h>

#include <memory>
#include <mutex>
#include <vector>

#include "capture_log.h"
#include "capture_reducer.h"
#include "footprint.h"
#include "vk_dispatch_table.h"

namespace asval {

class CapturePool : public CaptureSlabOwner, public std::enable_shared_from_this<CapturePool> {
 public:
  // Slabs are at least this large (a slab serves many captures of one recording).
  static constexpr VkDeviceSize kSlabBytes = VkDeviceSize{4} << 20;

  // `reduce`: the capture reduces on the device (capture_method, CaptureReduces); `gather`: the layer's dispatch
  // gathers the records of arrays of instance pointers (CaptureGathers). Either makes the reducer where the device
  // lets it be made; every slab then gets a device address and a place in the reducer's slab table.
  CapturePool(VkDevice device, const DeviceDispatchTable& next, const VkPhysicalDeviceMemoryProperties& memory,
              bool reduce = false, bool gather = false);
  ~CapturePool() override;

  // A slab of at least `bytes`; nullopt when the device cannot give one (no host-visible coherent memory type,
  // out of memory): the capture is then skipped and counted.
  bool Take(VkDeviceSize bytes, CaptureSlab* slab) override;
  void Return(const CaptureSlab& slab) override;
  // The capture points' events (capture_run.h), made on demand and reused; null where the device has no event
  // commands or the event cannot be made.
  VkEvent TakeEvent() override;
  void ReturnEvent(VkEvent event) override;
  // vkDestroyDevice: every slab is destroyed, also those still held by recordings (given back later: ignored).
  void Shutdown();
  // Adds its slabs to the layer's footprint (footprint.h).
  void AddFootprint(CaptureFootprint* out);
  // The capture reduces on the device (CaptureLog::TableIndexOf says where a slab is in the table).
  bool reduces() const { return reduces_; }
  // The layer's dispatch gathers arrays of instance pointers' records (also where the capture copies).
  bool gathers() const { return gathers_; }
  // The layer may bind its pipeline in the app's command buffers (and binds the app's compute pipeline again).
  bool dispatches() const { return reduces_ || gathers_; }
  // The reducing pipeline (compiled at the first call; null when it could not be: the captures are then copied).
  VkPipeline ReducePipeline() { return reducer_ ? reducer_->Pipeline() : VK_NULL_HANDLE; }

 private:
  bool Create(VkDeviceSize bytes, CaptureSlab* slab);
  void Destroy(const CaptureSlab& slab);

  const VkDevice device_;
  const DeviceDispatchTable& next_;
  uint32_t memory_type_ = UINT32_MAX;  // HOST_VISIBLE | HOST_COHERENT, HOST_CACHED preferred (the host reads)
  std::unique_ptr<CaptureReducer> reducer_;  // until Shutdown
  bool reduces_ = false;                     // set at construction
  bool gathers_ = false;                     // set at construction
  std::mutex mutex_;
  std::vector<CaptureSlab> free_;
  std::vector<CaptureSlab> all_;  // every live slab, for Shutdown
  std::size_t peak_in_use_ = 0;   // the most slabs taken at once (footprint)
  std::vector<VkEvent> free_events_;
  std::vector<VkEvent> all_events_;  // every event made, for Shutdown
  bool shut_down_ = false;
};

}  // namespace asval
