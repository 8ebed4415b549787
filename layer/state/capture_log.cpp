#include "capture_log.h"

#include <cstring>
#include <new>

namespace asval {

namespace {

constexpr VkDeviceSize kAlignment = 16;

}  // namespace

void CaptureLog::GiveBack() {
  for (const CaptureSlab& slab : slabs) owner_->Return(slab);
  for (VkEvent event : events_) owner_->ReturnEvent(event);
  slabs.clear();
  events_.clear();
}

void CaptureLog::Recycle() {
  GiveBack();
  used_.clear();
  bytes_captured = 0;
  infos.clear();
  geometries.clear();
  max_primitive_counts.clear();
  destinations.clear();
  blobs.clear();
  pending_submissions_ = 0;
  overlapped_ = false;
}

VkEvent CaptureLog::TakeEvent() {
  try {
    events_.reserve(events_.size() + 1);  // before the event is taken: one taken is one given back
  } catch (const std::bad_alloc&) {
    return VK_NULL_HANDLE;
  }
  const VkEvent event = owner_->TakeEvent();
  if (event != VK_NULL_HANDLE) events_.push_back(event);
  return event;
}

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

bool ExecutedGeometry(const CaptureLog& log, const CapturedInfo& info, uint32_t j, CapturedGeometry* out) {
  *out = log.geometries[info.first_geometry + j];
  if (!info.indirect_geometry) return true;
  if (!info.ranges.present || info.first_geometry + j >= log.max_primitive_counts.size()) return false;
  VkAccelerationStructureBuildRangeInfoKHR range;
  std::memcpy(&range, log.Bytes(info.ranges) + static_cast<std::size_t>(j) * info.indirect_stride, sizeof(range));
  const uint32_t n = range.primitiveCount;
  if (n > log.max_primitive_counts[info.first_geometry + j]) return false;
  CapturedGeometry& g = *out;
  // The offsets were applied on the device (reduce_inputs.comp): the results start where the dispatch wrote them.
  g.range = builder::BuildRange{};
  g.range.primitiveCount = n;
  if (!g.data.present) return true;
  if (g.array_of_pointers) {  // the pointers, then the records (GatheredBytes)
    g.pointers = CapturedBytes{g.pointers.slab, g.pointers.offset, 8 * VkDeviceSize{n}, true};
    g.data = CapturedBytes{g.pointers.slab, g.pointers.offset + g.pointers.size, 64 * VkDeviceSize{n}, true};
    return true;
  }
  const VkDeviceSize bits = ReducedBitBytes(g.type, n);
  const VkDeviceSize hashes = g.indices.present ? ReducedHashBytes(n) : 0;
  g.data.size = ReducedBytes(g.type, n, g.indices.present, g.transform.present);
  if (g.indices.present) g.indices = CapturedBytes{g.data.slab, g.data.offset + bits, hashes, true};
  if (g.transform.present) g.transform = CapturedBytes{g.data.slab, g.data.offset + bits + hashes, 48, true};
  return true;
}

MemorySpan ExecutedAccess(const CaptureLog& log, const CommandDestination& d) {
  if (!d.indirect || d.accessed.memory == VK_NULL_HANDLE) return d.accessed;
  if (d.counts_info == CommandDestination::kNoCountsInfo) return MemorySpan{};
  const CapturedInfo* info = log.Readable(d.counts_info);
  if (!info || !info->indirect || !info->ranges.present ||
      info->first_geometry + info->geometry_count > log.max_primitive_counts.size()) {
    return MemorySpan{};
  }
  for (uint32_t j = 0; j < info->geometry_count; ++j) {
    VkAccelerationStructureBuildRangeInfoKHR range;
    std::memcpy(&range, log.Bytes(info->ranges) + static_cast<std::size_t>(j) * info->indirect_stride,
                sizeof(range));
    if (range.primitiveCount != log.max_primitive_counts[info->first_geometry + j]) return MemorySpan{};
  }
  return d.accessed;
}

}  // namespace asval
