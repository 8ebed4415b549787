#include "capture_log.h"

namespace asval {

namespace {

constexpr VkDeviceSize kAlignment = 16;

}  // namespace

bool CaptureLog::Reserve(VkDeviceSize size, CapturedBytes* where) {
  const VkDeviceSize used = used_.empty() ? 0 : used_.back();
  const VkDeviceSize offset = (used + kAlignment - 1) & ~(kAlignment - 1);
  if (slabs.empty() || offset > slabs.back().size || size > slabs.back().size - offset) {
    // Room first: a slab taken and then not kept would be lost to the pool until the device goes.
    slabs.reserve(slabs.size() + 1);
    used_.reserve(slabs.size() + 1);
    CaptureSlab slab;
    if (!owner_->Take(size, &slab)) return false;
    slabs.push_back(slab);
    used_.push_back(0);
    return Reserve(size, where);
  }
  where->slab = static_cast<uint32_t>(slabs.size() - 1);
  where->offset = offset;
  where->size = size;
  where->present = true;
  used_.back() = offset + size;
  return true;
}

std::shared_ptr<CaptureLog> CaptureLog::EmptyCopy() const {
  auto copy = std::make_shared<CaptureLog>(owner_);
  copy->bytes_captured = bytes_captured;
  copy->infos = infos;
  copy->geometries = geometries;
  copy->max_primitive_counts = max_primitive_counts;
  copy->destinations = destinations;
  copy->blobs = blobs;
  copy->slabs.reserve(slabs.size());
  copy->used_ = used_;
  for (uint32_t k = 0; k < slabs.size(); ++k) {
    CaptureSlab slab;
    if (!owner_->Take(std::max<VkDeviceSize>(UsedBytes(k), 1), &slab)) return nullptr;  // gives back those taken
    copy->slabs.push_back(slab);
  }
  return copy;
}

uint32_t CaptureLog::AddInfo(CapturedInfo entry, const CapturedGeometry* info_geometries, const uint32_t* max_counts,
                             VkDeviceSize bytes) {
  entry.first_geometry = static_cast<uint32_t>(geometries.size());
  geometries.insert(geometries.end(), info_geometries, info_geometries + entry.geometry_count);
  if (max_counts) {
    max_primitive_counts.resize(geometries.size(), 0);
    std::copy(max_counts, max_counts + entry.geometry_count, max_primitive_counts.begin() + entry.first_geometry);
  }
  if (entry.complete) bytes_captured += bytes;
  infos.push_back(entry);
  return static_cast<uint32_t>(infos.size());
}

uint32_t CaptureLog::AddDestinations(const CommandDestination* command_destinations, uint32_t count) {
  const auto first = static_cast<uint32_t>(destinations.size());
  destinations.insert(destinations.end(), command_destinations, command_destinations + count);
  return first;
}

}  // namespace asval
