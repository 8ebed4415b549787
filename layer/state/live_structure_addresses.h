#pragma once
// The device addresses of the acceleration structures alive at one point of submission order (execution-time
// capture, issue 12): a top-level build's instances are checked against the structures that were alive when the
// build was submitted (pInfos-06707), once its captured instances are read. One sorted snapshot is shared by every
// submission until a structure is created or destroyed (the map's change stamp), so a frame that creates none
// costs a stamp compare.
#include <vulkan/vulkan.h>

#include <algorithm>
#include <cstddef>
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
  // structures[k] has addresses[k] (the record as it was when the snapshot was taken).
  std::vector<std::shared_ptr<const AccelerationStructureState>> structures;
  // Every live structure's address is known (the layer could ask for them all): otherwise an address not found
  // may belong to a structure whose address the layer does not know, and nothing is concluded from its absence.
  bool complete = true;
  // The index of the structure with this address, or -1.
  std::ptrdiff_t Find(VkDeviceAddress address) const {
    const auto it = std::lower_bound(addresses.begin(), addresses.end(), address);
    return it != addresses.end() && *it == address ? it - addresses.begin() : -1;
  }
  bool Contains(VkDeviceAddress address) const { return Find(address) >= 0; }
};

class LiveStructureAddressCache {
 public:
  using StructureMap = ConcurrentMap<VkAccelerationStructureKHR, std::shared_ptr<const AccelerationStructureState>>;

  std::shared_ptr<const LiveStructureAddresses> Get(const StructureMap& structures) const {
    std::lock_guard<std::mutex> lock(mutex_);
    const StampValue stamp = structures.stamp();
    if (cached_ && stamp == stamp_) return cached_;
    auto fresh = std::make_shared<LiveStructureAddresses>();
    std::vector<std::shared_ptr<const AccelerationStructureState>> live;
    for (auto& [handle, record] : structures.snapshot()) {
      if (!record || record->device_address == 0) {
        fresh->complete = false;
        continue;
      }
      live.push_back(std::move(record));
    }
    std::sort(live.begin(), live.end(), [](const auto& a, const auto& b) { return a->device_address < b->device_address; });
    fresh->addresses.reserve(live.size());
    for (const auto& record : live) fresh->addresses.push_back(record->device_address);
    fresh->structures = std::move(live);
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
