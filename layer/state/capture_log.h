#pragma once
// What one recording of a command buffer captured (execution-time capture, issue 12): for each captured build
// info, where the bytes its geometries are built from land in layer-owned host-visible memory when the command
// buffer executes, and how the reference builder must read them. The copies themselves are recorded by
// layer/capture, before the app's build; the bytes are read once the submission that ran them completes.
//
// Threads: written only by the thread recording the command buffer (the app synchronizes it); read after the
// recording was published (vkEndCommandBuffer), when a submission of it completes, under the device's capture
// processing lock (CaptureTracker, layer/capture).
#include <vulkan/vulkan.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <memory>
#include <vector>

#include "asval/builder/geometry_view.h"
#include "capture_skip.h"
#include "failure_counters.h"
#include "memory_range.h"

namespace asval {

// What the capture did on a device (DeviceState::capture_counters; shown in the history summary).
struct CaptureCounters {
  std::atomic<uint64_t> infos_captured{0};
  std::atomic<uint64_t> bytes_captured{0};
  // Infos a rule needed but that could not be captured, per reason (capture_skip.h); their total is the sum.
  std::array<std::atomic<uint64_t>, kCaptureSkipCount> infos_not_captured{};
  void NotCaptured(CaptureSkip why, uint64_t infos = 1) {
    if (infos != 0) infos_not_captured[SkipIndex(why)].fetch_add(infos, std::memory_order_relaxed);
  }
  uint64_t NotCapturedFor(CaptureSkip why) const {
    return infos_not_captured[SkipIndex(why)].load(std::memory_order_relaxed);
  }
  uint64_t InfosNotCaptured() const {
    uint64_t total = 0;
    for (const std::atomic<uint64_t>& n : infos_not_captured) total += n.load(std::memory_order_relaxed);
    return total;
  }
  // The points in command buffers where captures were recorded: one per run of build commands (capture_run.h) and
  // one per serialized blob.
  std::atomic<uint64_t> capture_points{0};
  // Updates whose activity rules (03663/03664/03768) were judged on captured bytes.
  std::atomic<uint64_t> updates_compared{0};
  // Device serialization bytes (vkCmdCopyAccelerationStructureToMemoryKHR's written, vkCmdCopyMemoryTo...'s read):
  // captured, and not captured (no copyable buffer, no slab, no room in the budget for the header).
  std::atomic<uint64_t> blobs_captured{0};
  std::atomic<uint64_t> blobs_not_captured{0};
  // Deserializations of device bytes whose history was restored once their captured bytes matched what the layer
  // saw serialized there; and those left unknown (bytes not captured in full, changed, or the destination
  // changed before the completion was processed).
  std::atomic<uint64_t> deserializations_restored{0};
  std::atomic<uint64_t> deserializations_unverified{0};
  // Whether infos not captured for capture_budget_mb (CaptureSkip::kOverBudget) were reported (once per device).
  std::atomic<bool> budget_reported{false};
  // The layer's own failures, capture or not (failure_counters.h): kept here because every writer reaches
  // DeviceState::capture_counters.
  FailureCounters failures;
};

// One block of layer-owned memory that the device copies build inputs into and the host reads.
struct CaptureSlab {
  VkBuffer buffer = VK_NULL_HANDLE;  // TRANSFER_DST, TRANSFER_SRC (and SHADER_DEVICE_ADDRESS when the capture reduces)
  VkDeviceMemory memory = VK_NULL_HANDLE;
  uint8_t* mapped = nullptr;  // host-visible, coherent, mapped for the slab's lifetime
  VkDeviceSize size = 0;
  // capture_method reduce (layer/capture/capture_reducer.h): the slab's device address, and its index in the
  // reducer's slab table (UINT32_MAX: not in it; what is captured into it is copied).
  VkDeviceAddress address = 0;
  uint32_t table_index = UINT32_MAX;
};

// Where slabs and the capture points' events come from and go back to (layer/capture's pool; destroyed with the
// device).
class CaptureSlabOwner {
 public:
  virtual ~CaptureSlabOwner() = default;
  // A slab of at least `bytes`; false when none can be had (the capture is then skipped and counted).
  virtual bool Take(VkDeviceSize bytes, CaptureSlab* slab) = 0;
  virtual void Return(const CaptureSlab& slab) = 0;
  // An unsignaled event; null when none can be had (the capture point then waits with a barrier).
  virtual VkEvent TakeEvent() { return VK_NULL_HANDLE; }
  // Given back unsignaled: every execution that set it reset it (capture_run_end.h).
  virtual void ReturnEvent(VkEvent) {}
};

// A range of captured bytes in the log's slabs; size 0 with present: nothing to read (no primitives).
struct CapturedBytes {
  uint32_t slab = 0;
  VkDeviceSize offset = 0;
  VkDeviceSize size = 0;
  bool present = false;  // false: not captured (no buffer the layer could copy from)
};

// One geometry as the builder reads it: the geometry's parameters with every offset the copy already applied
// removed (the captured bytes start where the build starts reading), and the bytes.
struct CapturedGeometry {
  VkGeometryTypeKHR type = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
  VkFormat vertex_format = VK_FORMAT_UNDEFINED;
  VkDeviceSize vertex_stride = 0;
  uint32_t max_vertex = 0;
  VkIndexType index_type = VK_INDEX_TYPE_NONE_KHR;
  VkDeviceSize aabb_stride = 0;
  // Instances given as an array of pointers: `pointers` holds the pointers (8 bytes each) the device read, and
  // `data`, where the layer's dispatch gathered them (layer/capture: GatherInstancePointers), the records they point
  // to, record k at 64 * k as in a plain array, so that everything after the capture reads them as one; a record
  // whose pointer is not followed (FollowedInstancePointer) is zeros there and unknown. `data` absent: the records
  // were not gathered (the capture copied the pointers only), their references and activity unknown.
  bool array_of_pointers = false;
  CapturedBytes pointers;
  // Indirect infos: what the range rules judge their captured range by (pIndirectDeviceAddresses-03651) was kept
  // when the command was recorded: type, and for triangles vertex_format, index_type and max_vertex, the app's
  // own (max_vertex not rewritten: firstVertex is in the range, on the device). False: the geometry could not be
  // read (a null element of ppGeometries); its range is not judged (skipped and counted). The bytes stay absent.
  bool range_facts = false;
  builder::BuildRange range;  // primitiveCount, and the offsets still to apply to the captured bytes
  CapturedBytes data;         // vertices (triangles) or AABB records
  CapturedBytes indices;      // indexed triangles
  CapturedBytes transform;    // triangles with a transform: its 48 bytes (for the warnings only; optional)
  // Triangles of a motion build (VkAccelerationStructureGeometryMotionTrianglesDataNV::vertexData): the vertices at
  // time 1, the same range as `data` reads. `motion` is known when the capture is planned (the bytes are present once
  // copied): such a geometry is copied, never reduced (the layer's dispatch reads one vertex set).
  bool motion = false;
  CapturedBytes motion_data;
  // capture_method reduce: `data` holds what the layer's dispatch wrote instead of the bytes (ReducedGeometry);
  // the indices and the transform are still copied.
  bool reduced = false;
};

// What the layer's dispatch wrote for a reduced geometry of `count` primitives (layer/capture/shaders/
// reduce_inputs.comp): instances first their records' accelerationStructureReference (8 bytes each); then three
// bit arrays of one bit per primitive in 32-bit words (bit t % 32 of word t / 32, zero past the count): active;
// undefined input (triangles: a NaN Y or Z with X not NaN; AABBs: a NaN other than minX) or, for instances, a NaN
// or infinite element in the transform; unreadable (an index naming a vertex above maxVertex, not read) or, for
// instances, per word the first non-finite transform's (lane << 4) | element. Instances then have, per 64 records,
// a summary of kReducedSummaryBytes: how many distinct references other than 0 they hold (a word, padded to 16
// bytes), then each of those once (16 bytes: the reference, the first of the 64 records holding it, padding), in no
// particular order. Indexed triangles then have, per 64 triangles, the hash of their index bytes
// (builder::HashIndexBlock: 16 bytes, lo then hi; CapturedGeometry::indices points there, kReducedHashBytes per
// block), which the host combines into the geometry's index hash, and triangles with a captured transform its 48
// bytes (CapturedGeometry::transform).
inline uint32_t ReducedWords(uint32_t count) { return (count + 31) / 32; }
inline constexpr VkDeviceSize kReducedSummaryBytes = 16 + 64 * 16;
inline VkDeviceSize ReducedBitBytes(VkGeometryTypeKHR type, uint32_t count) {
  const VkDeviceSize arrays = 3 * 4 * VkDeviceSize{ReducedWords(count)};
  if (type != VK_GEOMETRY_TYPE_INSTANCES_KHR) return arrays;
  return 8 * VkDeviceSize{count} + arrays + (VkDeviceSize{count} + 63) / 64 * kReducedSummaryBytes;
}
inline constexpr VkDeviceSize kReducedHashBytes = 16;
inline VkDeviceSize ReducedHashBytes(uint32_t count) { return (VkDeviceSize{count} + 63) / 64 * kReducedHashBytes; }
inline VkDeviceSize ReducedBytes(VkGeometryTypeKHR type, uint32_t count, bool indexed, bool transform) {
  return ReducedBitBytes(type, count) + (indexed ? ReducedHashBytes(count) : 0) + (transform ? 48 : 0);
}
struct ReducedGeometry {
  enum Array : uint32_t { kActive = 0, kUndefined = 1, kNonFinite = 1, kUnreadable = 2, kFirstNonFinite = 2 };
  const uint8_t* base;
  uint32_t count;
  bool instances;
  // Word w of bit array a.
  uint32_t Word(Array a, uint32_t w) const {
    uint32_t v;
    std::memcpy(&v, ArrayBytes(a) + 4 * VkDeviceSize{w}, sizeof(v));
    return v;
  }
  // Bit array a: ReducedWords(count) little-endian words.
  const uint8_t* ArrayBytes(Array a) const { return Arrays() + 4 * VkDeviceSize{a} * ReducedWords(count); }
  // Instances: the references.
  const uint8_t* references() const { return base; }
  // Instances: the summary of records 64 * group .. 64 * group + 63: how many distinct references, and each.
  uint32_t Distinct(uint32_t group) const {
    uint32_t v;
    std::memcpy(&v, Summary(group), sizeof(v));
    return v;
  }
  void DistinctReference(uint32_t group, uint32_t entry, uint64_t* reference, uint32_t* first) const {
    const uint8_t* e = Summary(group) + 16 + 16 * VkDeviceSize{entry};
    std::memcpy(reference, e, sizeof(*reference));
    std::memcpy(first, e + 8, sizeof(*first));
  }

 private:
  // The three bit arrays follow the instances' references; the summaries follow the arrays.
  const uint8_t* Arrays() const { return base + (instances ? 8 * VkDeviceSize{count} : 0); }
  const uint8_t* Summary(uint32_t group) const {
    return Arrays() + 3 * 4 * VkDeviceSize{ReducedWords(count)} + VkDeviceSize{group} * kReducedSummaryBytes;
  }
};

// A destination of a build command that has a captured top-level info among several: what the rules about one
// command's instances and its other destinations need (None-03407, dstAccelerationStructure-03706), as resolved
// when the command was recorded (a destination cannot move while the build is pending).
struct CommandDestination {
  VkAccelerationStructureKHR handle = VK_NULL_HANDLE;
  uint32_t element = 0;         // its index in pInfos
  VkDeviceAddress address = 0;  // 0: unknown
  MemorySpan accessed;          // the bytes this build writes (accelerationStructureSize); memory null: unknown
  // Indirect commands: `accessed` is the size for ppMaxPrimitiveCounts, the bytes the build writes only when the
  // range infos the device read hold those very counts; they are in CaptureLog::infos[counts_info] (kNoInfo: this
  // info has no geometry, or its range infos were not captured, and `accessed` is then known or unknown as is).
  bool indirect = false;
  uint32_t counts_info = kNoCountsInfo;
  static constexpr uint32_t kNoCountsInfo = UINT32_MAX;
};

// Whether the layer's dispatch reads the record an instance pointer names (shaders/reduce_inputs.comp decides the
// same): not 0 and aligned to 16 bytes (pInfos-03717; a misaligned one is reported, never chased). The build
// itself reads 64 bytes there (the dispatch runs after it, or beside it): the dispatch reads nothing the build would
// not read.
inline bool FollowedInstancePointer(uint64_t pointer) { return pointer != 0 && pointer % 16 == 0; }
inline uint64_t InstancePointer(const uint8_t* pointers, uint32_t k) {
  uint64_t pointer = 0;
  std::memcpy(&pointer, pointers + 8 * static_cast<std::size_t>(k), sizeof(pointer));
  return pointer;
}
// What the gathering job writes for `count` pointers: the pointers, then the records (ReduceJob::kGatherInstances).
inline VkDeviceSize GatheredBytes(uint32_t count) { return (8 + 64) * VkDeviceSize{count}; }

// One captured build info (pInfos[i] of a recorded build command).
struct CapturedInfo {
  uint32_t first_geometry = 0;  // into CaptureLog::geometries
  uint32_t geometry_count = 0;
  uint32_t element = 0;  // its index in pInfos
  // Top-level infos of a command of several infos: the command's destinations (all of them, this info's own
  // included) in CaptureLog::destinations; count 0 otherwise.
  uint32_t first_destination = 0;
  uint32_t destination_count = 0;
  // Indirect builds: the range infos read from pIndirectDeviceAddresses[i], geometry j's at j * indirect_stride,
  // and ppMaxPrimitiveCounts[i][j] as recorded (in max_primitive_counts, from first_geometry on).
  bool indirect = false;
  CapturedBytes ranges;
  uint32_t indirect_stride = 0;
  // Indirect infos whose geometries the layer's dispatch also read (issue 28): each planned for the most
  // primitives the build may read, its range info read on the device (ExecutedGeometry gives it as built). False:
  // the range infos alone (what it built from is unknown).
  bool indirect_geometry = false;
  // Every geometry's bytes are captured (else the info's activity is unknown: counted, never guessed).
  bool complete = true;
};

class CaptureLog;

// Geometry j of a captured info as the build read it: for an indirect info whose geometries were captured
// (CapturedInfo::indirect_geometry), the planned geometry with its range info as the device read it (copied into
// CapturedInfo::ranges) and the bytes the layer's dispatch laid out for that range's count; else the geometry as
// logged. False when the count is above ppMaxPrimitiveCounts (the dispatch read no more than the maximum: what the
// build read is unknown; the count's own rule reports it) or the range infos were not captured.
bool ExecutedGeometry(const CaptureLog& log, const CapturedInfo& info, uint32_t j, CapturedGeometry* out);

// The bytes destination d of a command writes, as the device executed it: `accessed`, except for an indirect
// command whose range infos for d hold other counts than ppMaxPrimitiveCounts (or were not captured): unknown
// (memory null).
MemorySpan ExecutedAccess(const CaptureLog& log, const CommandDestination& d);

class CaptureLog : public std::enable_shared_from_this<CaptureLog> {
 public:
  explicit CaptureLog(std::shared_ptr<CaptureSlabOwner> owner) : owner_(std::move(owner)) {}
  ~CaptureLog() { GiveBack(); }
  CaptureLog(const CaptureLog&) = delete;
  CaptureLog& operator=(const CaptureLog&) = delete;

  const uint8_t* Bytes(const CapturedBytes& bytes) const { return slabs[bytes.slab].mapped + bytes.offset; }
  ReducedGeometry Reduced(const CapturedGeometry& g) const {
    return ReducedGeometry{Bytes(g.data), g.range.primitiveCount, g.type == VK_GEOMETRY_TYPE_INSTANCES_KHR};
  }
  // The slab's buffer the device copies `bytes` into.
  VkBuffer BufferOf(const CapturedBytes& bytes) const { return slabs[bytes.slab].buffer; }
  // capture_method reduce: where the device writes `bytes`, and their slab's index in the reducer's table.
  VkDeviceAddress AddressOf(const CapturedBytes& bytes) const { return slabs[bytes.slab].address + bytes.offset; }
  uint32_t TableIndexOf(const CapturedBytes& bytes) const { return slabs[bytes.slab].table_index; }
  // The recording thread writes a reduce job's parameters (before any submission reads them).
  uint8_t* WritableBytes(const CapturedBytes& bytes) { return slabs[bytes.slab].mapped + bytes.offset; }
  // An event for one run's capture point (capture_run.h), the log's until it is destroyed: no submission reads the
  // recording any more then, so every execution of it has reset the event. Null when none can be had.
  VkEvent TakeEvent();
  // The log emptied for another recording of its command buffer, its vectors' storage kept; its slabs and events go
  // back to the owner. Only where nothing else holds the log (no submission reads it).
  void Recycle();
  const std::shared_ptr<CaptureSlabOwner>& owner() const { return owner_; }

  // ---- written by the recording thread (layer/capture's pre-record, through these) ----
  // Room for `size` bytes, 16-aligned, in the last slab or a new one; *where is set and marked present. False
  // when no slab could be had.
  bool Reserve(VkDeviceSize size, CapturedBytes* where);
  // Appends one captured info with its geometries (and, for an indirect info, the recorded maximum counts, one
  // per geometry; else null); `bytes` of its captures count against the recording's budget. Returns its index
  // in `infos` plus one (what AsOp::capture_info is taken from).
  uint32_t AddInfo(CapturedInfo entry, const CapturedGeometry* info_geometries, const uint32_t* max_counts,
                   VkDeviceSize bytes);
  // Appends the destinations of the command being recorded; returns the index of the first (for
  // CapturedInfo::first_destination).
  uint32_t AddDestinations(const CommandDestination* command_destinations, uint32_t count);
  // Appends the captured bytes of one device serialization's blob (from its start; `bytes.size` of them, which
  // may be less than the blob when the budget or the buffer ended first); they count against the budget.
  // Returns its index in `blobs` plus one.
  uint32_t AddBlob(const CapturedBytes& bytes) {
    bytes_captured += bytes.size;
    blobs.push_back(bytes);
    return static_cast<uint32_t>(blobs.size());
  }

  // ---- a secondary executed again by one primary (layer/capture/capture_saves.h) ----
  // How many bytes of slabs[slab] the captures use (from its start): what a save copies.
  VkDeviceSize UsedBytes(uint32_t slab) const { return slab < used_.size() ? used_[slab] : 0; }
  // A log with the same captures (infos, geometries, destinations, blobs) in slabs of its own, each as large as
  // this log's use of the slab of the same index: what the device copies this log's bytes into, so that they are
  // read from there once an execution of the recording wrote them and before the next writes them again. Null
  // when the pool gives no slab; throws std::bad_alloc.
  std::shared_ptr<CaptureLog> EmptyCopy() const;

  // ---- under the capture processing lock (CaptureTracker) ----
  // A submission that reads this recording's captures is about to be made / was processed or not made. A second
  // one while the first is pending (a SIMULTANEOUS_USE command buffer) makes the device write the same bytes
  // twice before the layer reads them: every capture of the recording is then unknown until none is pending.
  void SubmissionStarted() {
    if (pending_submissions_ > 0) overlapped_ = true;
    ++pending_submissions_;
  }
  void SubmissionEnded() {
    if (--pending_submissions_ == 0) overlapped_ = false;
  }
  bool overlapped() const { return overlapped_; }
  // infos[info] when its bytes can be read as the device wrote them: every geometry captured, and not written
  // again before being read; else null (the rules that need it are skipped and counted).
  const CapturedInfo* Readable(uint32_t info) const {
    return !overlapped_ && info < infos.size() && infos[info].complete ? &infos[info] : nullptr;
  }
  // blobs[blob] when its bytes can be read as the device wrote them (as Readable).
  const CapturedBytes* ReadableBlob(uint32_t blob) const {
    return !overlapped_ && blob < blobs.size() && blobs[blob].present ? &blobs[blob] : nullptr;
  }

  // How many infos and geometries the log holds: a command buffer recorded again (every frame, typically)
  // reserves what its last recording used, so that its build commands do not grow the vectors step by step.
  struct Size {
    std::size_t infos = 0;
    std::size_t geometries = 0;
  };
  Size RecordCounts() const { return {infos.size(), geometries.size()}; }
  void ReserveRecords(const Size& size) {
    infos.reserve(size.infos);
    geometries.reserve(size.geometries);
  }

  std::vector<CaptureSlab> slabs;
  VkDeviceSize bytes_captured = 0;
  std::vector<CapturedInfo> infos;
  std::vector<CapturedGeometry> geometries;
  std::vector<uint32_t> max_primitive_counts;  // parallel to geometries (indirect infos only; else 0)
  std::vector<CommandDestination> destinations;
  // Serialized bytes copied from device memory (a serialization's blob after it executed, a deserialization's
  // before it executed); AsOp::capture_info of a kSerialize / kDeserialize operation indexes this.
  std::vector<CapturedBytes> blobs;

 private:
  void GiveBack();  // the slabs and events, to the owner

  std::shared_ptr<CaptureSlabOwner> owner_;
  std::vector<VkDeviceSize> used_;  // per slab, the bytes its captures use (from its start)
  std::vector<VkEvent> events_;     // TakeEvent's, given back with the log
  uint32_t pending_submissions_ = 0;
  bool overlapped_ = false;
};

}  // namespace asval
