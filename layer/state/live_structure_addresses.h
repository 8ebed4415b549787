#pragma once
// The device addresses of the acceleration structures alive at one point of submission order (execution-time
// capture, issue 12): a top-level build's instances are checked against the structures that were alive when the
// build was submitted (pInfos-06707), once its captured instances are read. One sorted snapshot is shared by every
// submission until a structure is created or destroyed (the map's change stamp), so a frame that creates none
// costs a stamp compare.
#include <vulkan/vulkan.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "change_stamp.h"
#include "concurrent_map.h"
#include "objects.h"

namespace asval {

struct LiveStructureAddresses {
  std::vector<VkDeviceAddress> addresses;  // sorted
  // Every live structure's address is known (the layer could ask for them all): otherwise an address not found
  // may belong to a structure whose address the layer does not know, and nothing is concluded from its absence.
  bool complete = true;
  bool Contains(VkDeviceAddress address) const {
    return std::binary_search(addresses.begin(), addresses.end(), address);
  }
};

class LiveStructureAddressCache {
 public:
  using StructureMap = ConcurrentMap<VkAccelerationStructureKHR, std::shared_ptr<const AccelerationStructureState>>;

  std::shared_ptr<const LiveStructureAddresses> Get(const StructureMap& structures) const {
    std::lock_guard<std::mutex> lock(mutex_);
    const StampValue stamp = structures.stamp();
    if (cached_ && stamp == stamp_) return cached_;
    auto fresh = std::make_shared<LiveStructureAddresses>();
    for (const auto& [handle, record] : structures.snapshot()) {
      if (!record || record->device_address == 0) {
        fresh->complete = false;
        continue;
      }
      fresh->addresses.push_back(record->device_address);
    }
    std::sort(fresh->addresses.begin(), fresh->addresses.end());
    cached_ = std::move(fresh);
    stamp_ = stamp;
    return cached_;
  }

 private:
  mutable std::mutex mutex_;
  mutable std::shared_ptr<const LiveStructureAddresses> cached_;
  mutable StampValue stamp_{};
};

}  // namespace asval
