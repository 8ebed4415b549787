#pragma once
// The primitive activity of one executed build or update (issue 12): per geometry, which primitives were active
// (the reference builder's ActivityRecord: one bit per primitive, and a fingerprint of the index values), read
// from the bytes the layer captured when the build executed. A structure's history holds the activity of the
// build that last executed on it (AsHistory::activity); an update is compared with its source's.
//
// Created pending when a submission is applied (submission order), filled when that submission completes
// (CaptureTracker, layer/capture), in submission order, under the device's capture processing lock, which every
// reader holds too.
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <map>
#include <memory>
#include <vector>

#include "asval/builder/activity_record.h"
#include "capture_log.h"
#include "command_buffer_ops.h"
#include "live_structure_addresses.h"

namespace asval {

struct BuildSnapshot;  // history.h (which includes this file)

// The first NaN or infinite element of a 3x4 row-major float matrix as captured (VkTransformMatrixKHR, the
// transform of an instance record), as row * 4 + column; -1 when all twelve are finite.
int FirstNonFiniteElement(const uint8_t* matrix);
// Whether all twelve elements of such a matrix are finite (a float is NaN or infinite exactly when its exponent bits
// are all set): inline and branch-free, so that a scan over thousands of instance records vectorizes.
inline bool AllFinite(const uint8_t* matrix) {
  constexpr uint32_t kExponent = 0x7f800000u;
  uint32_t words[12];
  std::memcpy(words, matrix, sizeof(words));
  uint32_t any = 0;
  for (uint32_t w : words) any |= static_cast<uint32_t>((w & kExponent) == kExponent);
  return any == 0;
}

// The distance from |x| to the next larger 32-bit float: how finely positions near x can be placed.
float FloatSpacingAt(float x);
// Whether float spacing at `magnitude` exceeds permille / 1000 of `size` (ASVAL-Capture-FloatSpacing).
bool SpacingExceeds(float magnitude, float size, uint32_t permille);

// The structures a top-level build's instances referenced (issue 29, family traces): each distinct one with its
// serial (AccelerationStructureState::serial), as the capture found them when the build's submission completed,
// and the build that had last executed on it then (its snapshot and history generation; null: not known). A trace
// of the top level walks them to see that each is still alive, its storage still bound, and not rebuilt since with
// another geometry layout. The sum of the change stamps that can alter that answer (structures created or destroyed,
// storage bound or freed, bottom-level layouts replaced), plus one, at the last walk that found nothing is kept,
// and while it reads the same no walk is needed (0: never).
struct ReferencedStructures {
  struct Referenced {
    VkAccelerationStructureKHR as = VK_NULL_HANDLE;
    uint64_t serial = 0;
    std::shared_ptr<const BuildSnapshot> build;
    uint64_t generation = 0;
  };
  std::vector<Referenced> structures;  // ordered by handle once published (RememberReferencedBuilds)
  mutable std::atomic<uint64_t> verified_structures{0};

  // The entry of `as`, or null.
  const Referenced* Find(VkAccelerationStructureKHR as) const {
    const auto at = std::lower_bound(structures.begin(), structures.end(), as,
                                     [](const Referenced& r, VkAccelerationStructureKHR h) { return r.as < h; });
    return at != structures.end() && at->as == as ? &*at : nullptr;
  }
};

class BuildActivity {
 public:
  enum class Status : uint8_t { kPending, kReady, kUnknown };

  // Input the specification leaves undefined, found while classifying one geometry (a warning, not a rule).
  struct UndefinedInput {
    uint32_t geometry = 0;
    uint32_t primitives = 0;  // triangles with a NaN Y or Z while X is not NaN (AABBs: NaN outside minX)
    uint32_t first_primitive = 0;
    int transform_element = -1;  // triangles: the first NaN or infinite element of the transform (row * 4 + col)
  };

  // Primitives whose coordinates are so large that 32-bit floats there are spaced more than a fraction of the
  // primitive's size apart (a warning, not a rule): per geometry, counted, the first named.
  struct CoarseSpacing {
    uint32_t geometry = 0;
    uint32_t primitives = 0;
    uint32_t first_primitive = 0;
    float magnitude = 0;  // the first one's largest coordinate
    float size = 0;       // and its size (its box's largest extent)
  };

  BuildActivity(std::shared_ptr<const CaptureLog> log, uint32_t info, const OpOrigin& origin,
                VkAccelerationStructureKHR dst)
      : log_(std::move(log)), info_(info), origin_(origin), dst_(dst) {}

  // Acquire: a reader that sees kReady also sees the records Fill wrote (a host update compares its inputs with a
  // source's activity outside the capture processing lock).
  Status status() const { return status_.load(std::memory_order_acquire); }
  // kReady: one record per geometry of the build.
  const std::vector<builder::ActivityRecord>& geometries() const { return geometries_; }

  // Classifies the captured bytes (the submission completed). Geometries the builder cannot classify (a format
  // it does not decode, bytes not captured) leave the whole activity unknown. spacing_permille > 0 also scans the
  // triangles and AABBs for coarse float spacing (coarse_spacing()): a second pass, so only when asked.
  void Fill(uint32_t spacing_permille = 0);
  // Top-level builds: what its instances referenced, set once when its submission completed (after the instance
  // rules judged them); null before, or when not all references named known structures. Readable without the
  // processing lock (release/acquire).
  void SetReferences(std::shared_ptr<const ReferencedStructures> references) {
    std::atomic_store_explicit(&references_, std::move(references), std::memory_order_release);
  }
  std::shared_ptr<const ReferencedStructures> references() const {
    return std::atomic_load_explicit(&references_, std::memory_order_acquire);
  }
  // The submission that applied this build (SubmissionCaptures::id; 0: none known).
  uint64_t submission() const { return submission_; }
  void SetSubmission(uint64_t id) { submission_ = id; }
  // The bytes cannot be trusted (the same capture written twice before it was read): unknown.
  void MarkUnknown() {
    status_.store(Status::kUnknown, std::memory_order_release);
    log_.reset();
  }
  // The build (or update) this is the activity of.
  const OpOrigin& origin() const { return origin_; }
  VkAccelerationStructureKHR dst() const { return dst_; }
  // kReady: the geometries with undefined input (usually none).
  const std::vector<UndefinedInput>& undefined_input() const { return undefined_; }
  // kReady, when Fill scanned for it: the geometries with coarsely spaced primitives (usually none).
  const std::vector<CoarseSpacing>& coarse_spacing() const { return coarse_; }
  // kReady, when Fill scanned for spacing: the smallest positive size (box extent) of its primitives; 0 when
  // none or not scanned. An instance of it is judged by it (its translation's float spacing).
  float smallest_primitive() const { return smallest_; }
  // kReady: no geometry has an active primitive (an instance of it is degenerate).
  bool NoActivePrimitive() const;

 private:
  void ScanSpacing(const CaptureLog& log, const CapturedInfo& info, uint32_t permille);

  std::atomic<Status> status_{Status::kPending};
  std::shared_ptr<const CaptureLog> log_;  // until filled
  uint32_t info_ = 0;
  std::vector<builder::ActivityRecord> geometries_;
  std::vector<UndefinedInput> undefined_;
  std::vector<CoarseSpacing> coarse_;
  float smallest_ = 0;
  OpOrigin origin_;
  VkAccelerationStructureKHR dst_ = VK_NULL_HANDLE;
  std::shared_ptr<const ReferencedStructures> references_;
  uint64_t submission_ = 0;
};

// An update to compare with the activity of its source's last executed build (pInfos-03663, 03664, 03768).
struct ActivityComparison {
  std::shared_ptr<BuildActivity> before;  // null: the source's last build was not captured
  std::shared_ptr<BuildActivity> after;   // the update's own activity
  OpOrigin update;                        // the update (for messages)
  OpOrigin source_build;                  // the build that produced `before` (for messages)
  VkAccelerationStructureKHR src = VK_NULL_HANDLE;
  VkAccelerationStructureKHR dst = VK_NULL_HANDLE;
};

// A top-level build whose instances' references must name structures alive when it was submitted (06707).
struct InstanceReferenceCheck {
  std::shared_ptr<const CaptureLog> log;  // its captured instances
  uint32_t info = 0;                      // in log->infos
  std::shared_ptr<const LiveStructureAddresses> live;
  // When degenerate instances are reported (DeviceState::instance_activity_snapshots): per structure of `live`,
  // the activity of the build that last executed on it as of this build's submission (null: not captured);
  // else empty.
  std::vector<std::shared_ptr<const BuildActivity>> activities;
  OpOrigin build;
  VkAccelerationStructureKHR dst = VK_NULL_HANDLE;
  // The build's activity node (the history's record of it): gets the structures the instances referenced.
  std::shared_ptr<BuildActivity> activity;
};

// An indirect build whose range infos, read by the device, must respect ppMaxPrimitiveCounts (03653); for an
// update, each geometry's primitiveCount must also be its source's last build's (primitiveCount-03769).
struct IndirectRangeCheck {
  std::shared_ptr<const CaptureLog> log;
  uint32_t info = 0;
  OpOrigin build;
  VkAccelerationStructureKHR dst = VK_NULL_HANDLE;
  // Updates: srcAccelerationStructure and its last build as the history held it when the update was applied
  // (submission order; shared, immutable). Null for builds, and for updates whose source has no last build to
  // compare with: never built (03667) or unknown, which the update rules reported or counted at submission.
  VkAccelerationStructureKHR src = VK_NULL_HANDLE;
  std::shared_ptr<const BuildSnapshot> source;
};

// The content of the bytes a device serialization wrote (issue 12): the size its header gives and the hash of
// exactly that many bytes, from the bytes captured after the serialization executed. Created pending when the
// serialization is applied (submission order) and shared by the blob in the history store and the deserializations
// applied after it; filled (or made unknown) when the serialization's submission completes, under the device's
// capture processing lock, which every reader holds too.
struct SerializedContent {
  enum class Status : uint8_t { kPending, kReady, kUnknown };
  Status status = Status::kPending;
  uint64_t size = 0;
  uint64_t hash = 0;
};

// A device serialization whose written bytes were captured (log->blobs[blob]): its content, filled at completion.
struct SerializeCapture {
  std::shared_ptr<const CaptureLog> log;
  uint32_t blob = 0;
  std::shared_ptr<SerializedContent> content;
  bool read_twice = false;  // the same capture read twice by one submission: unknown
};

// A device deserialization whose read bytes were captured (log->blobs[blob]), from where the layer saw a
// serialization (still valid when the deserialization was applied): dst gets the serialized structure's history
// back only when the bytes it read hash to that serialization's content, and dst's contents did not change since.
struct DeserializeCheck {
  std::shared_ptr<const CaptureLog> log;
  uint32_t blob = 0;
  std::shared_ptr<const SerializedContent> expected;
  std::shared_ptr<const BuildSnapshot> build;  // the serialized structure's last build, as the blob holds it
  std::shared_ptr<BuildActivity> activity;     // ... and its activity (null when not captured)
  VkAccelerationStructureKHR dst = VK_NULL_HANDLE;
  uint64_t generation = 0;  // dst's contents generation that the deserialization gave it
  bool read_twice = false;  // the same capture read twice by one submission: unknown
};

// What one submission's captures ask for once it completes, in submission order.
struct SubmissionCaptures {
  // This submission's id (device-wide unique, DeviceState::NextObjectId; 0: none): the activity records it creates
  // carry it (BuildActivity::submission), so that a trace in the same submission knows a build pending beside it.
  uint64_t id = 0;
  std::vector<std::shared_ptr<BuildActivity>> fills;
  std::vector<ActivityComparison> comparisons;
  std::vector<InstanceReferenceCheck> instance_checks;
  std::vector<IndirectRangeCheck> indirect_checks;
  // Serializations and deserializations of device bytes (filled and judged in that order: a deserialization in
  // the same submission as the serialization it reads comes after it).
  std::vector<SerializeCapture> serializes;
  std::vector<DeserializeCheck> deserializes;
  // The recordings whose captures this submission reads (each counted once as pending: CaptureLog::SubmissionStarted).
  std::vector<std::shared_ptr<CaptureLog>> logs;
  // Each capture read once per submission (history_apply.cpp).
  std::map<std::pair<const CaptureLog*, uint32_t>, BuildActivity*> claimed;
  // Where a submission whose captures cannot be read counts them (the device's; set by HistorySubmission).
  FailureCounters* failures = nullptr;
  bool empty() const { return fills.empty() && serializes.empty() && deserializes.empty(); }
};

}  // namespace asval
