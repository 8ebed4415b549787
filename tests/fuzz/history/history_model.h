#pragma once
// The reference model of the build history for asval_fuzz_history: plain maps of what each structure's last
// executed operation left (built or not, the build's parameters, clobbered, the serialization size read back),
// written from docs/history.md and the rules' needs (layer/checks/update_rules.cpp), independently of
// layer/state. Spans are compared by brute force, serialized host bytes by their contents (not a hash), so that
// the store's shortcuts (record slots, handle index, "alone" epochs, remembered snapshots) are checked against
// the plain meaning.
#include <vulkan/vulkan.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <optional>
#include <utility>
#include <vector>

namespace asval::fuzz {

constexpr uint32_t kHandles = 6;      // structure handle values (reused after destruction)
constexpr uint32_t kHostBlobs = 3;    // host arrays that serialized data is written to and read from
constexpr uint32_t kHostBlobBytes = 96;

// One geometry as an update must repeat it (the fields of asval::GeometryRecord, written by the fuzz target
// from what it put in the build info, not read back from the layer).
struct ModelGeometry {
  VkGeometryTypeKHR type = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
  VkGeometryFlagsKHR flags = 0;
  VkFormat vertex_format = VK_FORMAT_UNDEFINED;
  VkIndexType index_type = VK_INDEX_TYPE_NONE_KHR;
  uint32_t max_vertex = 0;
  uint32_t primitive_count = 0;
  bool has_transform = false;
  bool count_known = true;
};

struct ModelParams {
  VkBuildAccelerationStructureFlagsKHR flags = 0;
  VkAccelerationStructureTypeKHR type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  std::vector<ModelGeometry> geometries;
};

enum class ModelKind { kNeverBuilt, kBuilt, kUnknown };
enum class ModelUnknown { kNone, kDeserializedUnknownBytes, kDeserializedDeviceBytes, kCopiedFromUnknown,
                          kLostOperations, kUnreadableBuild,
                          kStaleHandle };  // a device command recorded before its structure's handle was reused

struct ModelHistory {
  ModelKind kind = ModelKind::kNeverBuilt;
  ModelUnknown reason = ModelUnknown::kNone;
  ModelParams params;        // kBuilt
  bool clobbered = false;
  uint64_t contents = 0;     // a model-wide unique id per write of the contents (0: never written)
  std::optional<uint64_t> serialization_size;  // read back for these contents
};

// One recorded operation, as the fuzz target recorded it.
struct ModelOp {
  enum Kind { kBuild, kCopy, kSerializeDevice, kDeserializeDevice, kSerializeHost, kDeserializeHost,
              kWriteProperties } kind = kBuild;
  uint32_t src = 0, dst = 0;  // handle indices
  bool update = false;
  bool indirect = false;
  bool compact = false;       // kCopy: VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR
  bool unreadable = false;
  ModelParams params;
  // kSerializeDevice: the memory bytes [begin, end) the destination reaches (end: the buffer's end).
  bool has_span = false;
  uint64_t begin = 0, end = 0;
  uint32_t blob = 0;             // host serialization: which host array
  uint32_t pool_query = 0;       // kWriteProperties: the slot
  VkQueryType query_type = VK_QUERY_TYPE_OCCLUSION;
  // Model::clock when a device command recorded it (0: a host call): a structure created later under one of its
  // handles is not the one it named (its command buffer is invalid; what it does there is unknown).
  uint64_t recorded_at = 0;
};

struct ModelBlob {
  uint32_t id = 0;
  bool device = false;        // device memory [begin, end) (else host array `host`)
  uint64_t begin = 0, end = 0;
  uint32_t host = 0;  // which host array
  std::vector<uint8_t> bytes;
  ModelHistory history;
  bool valid = true;
};

struct ModelSlot {
  uint32_t as = 0;
  uint64_t contents = 0;  // of as when the property write executed (0: never written)
  VkQueryType type = VK_QUERY_TYPE_OCCLUSION;
};

struct ModelStructure {
  bool live = false;
  uint64_t created = 0;  // Model::clock at its creation
  uint64_t begin = 0, end = 0;  // its VkDeviceMemory bytes
  ModelHistory history;
};

// Everything the model knows; copyable, so that a submission's undo is compared with the state before it.
struct Model {
  ModelStructure structures[kHandles];
  std::vector<ModelBlob> blobs;
  std::map<uint32_t, ModelSlot> slots;
  uint64_t next_contents = 0;
  uint64_t clock = 1;  // counts creations (a device command's recorded_at is never 0)
  uint32_t next_blob = 0;
  // During a submission (undoable): what it added or invalidated, and the structures host operations completing
  // meanwhile changed (those keep their newer history when the submission is undone).
  bool in_submission = false;
  std::vector<uint32_t> blobs_added, blobs_invalidated;
  bool changed_after[kHandles] = {};

  bool Same(const ModelParams& a, const ModelParams& b) const {
    if (a.flags != b.flags || a.type != b.type || a.geometries.size() != b.geometries.size()) return false;
    for (size_t j = 0; j < a.geometries.size(); ++j) {
      const ModelGeometry& x = a.geometries[j];
      const ModelGeometry& y = b.geometries[j];
      if (x.type != y.type || x.flags != y.flags || x.vertex_format != y.vertex_format ||
          x.index_type != y.index_type || x.max_vertex != y.max_vertex || x.has_transform != y.has_transform ||
          x.count_known != y.count_known || (x.count_known && x.primitive_count != y.primitive_count)) {
        return false;
      }
    }
    return true;
  }
  // An indirect update repeats its source when everything but the counts it does not know matches.
  bool Repeats(const ModelParams& source, const ModelParams& update) const {
    if (source.flags != update.flags || source.type != update.type ||
        source.geometries.size() != update.geometries.size()) {
      return false;
    }
    ModelParams merged = update;
    for (size_t j = 0; j < merged.geometries.size(); ++j) {
      if (!merged.geometries[j].count_known) {
        merged.geometries[j].primitive_count = source.geometries[j].primitive_count;
        merged.geometries[j].count_known = source.geometries[j].count_known;
      }
    }
    return Same(source, merged);
  }

  void Touch(uint32_t as) {
    if (!in_submission) changed_after[as] = true;
  }
  // A structure's contents written: a new history, then every other written structure over its bytes is
  // clobbered, and serialized bytes there are no longer valid (host bytes have no memory span).
  void Write(uint32_t as, ModelHistory history) {
    ModelStructure& s = structures[as];
    history.contents = ++next_contents;
    s.history = std::move(history);
    Touch(as);
    ClobberRange(s.begin, s.end, as);
  }
  void ClobberRange(uint64_t begin, uint64_t end, std::optional<uint32_t> except) {
    InvalidateDeviceBlobs(begin, end);
    if (begin >= end) return;  // an empty range overlaps nothing
    for (uint32_t o = 0; o < kHandles; ++o) {
      if (except && o == *except) continue;
      ModelStructure& other = structures[o];
      if (!other.live || other.history.kind == ModelKind::kNeverBuilt || other.history.clobbered) continue;
      if (other.begin < end && begin < other.end) {
        other.history.clobbered = true;
        Touch(o);
      }
    }
  }
  void Invalidate(ModelBlob& blob) {
    if (!blob.valid) return;
    blob.valid = false;
    if (in_submission) blobs_invalidated.push_back(blob.id);
  }
  void InvalidateDeviceBlobs(uint64_t begin, uint64_t end) {
    for (ModelBlob& b : blobs) {
      if (b.device && b.begin < b.end && begin < end && b.begin < end && begin < b.end) Invalidate(b);
    }
  }
  const ModelBlob* LatestHostBlob(uint32_t host) const {
    for (auto it = blobs.rbegin(); it != blobs.rend(); ++it) {
      if (it->valid && !it->device && it->host == host) return &*it;
    }
    return nullptr;
  }
  const ModelBlob* LatestDeviceBlob(uint64_t begin) const {
    for (auto it = blobs.rbegin(); it != blobs.rend(); ++it) {
      if (it->valid && it->device && it->begin == begin) return &*it;
    }
    return nullptr;
  }
  // The store keeps at most 64 blobs before it drops the invalid ones (they can restore nothing).
  void AddBlob(ModelBlob blob) {
    if (blobs.size() >= 64) {
      std::vector<ModelBlob> kept;
      for (ModelBlob& b : blobs) {
        if (b.valid) kept.push_back(std::move(b));
      }
      blobs = std::move(kept);
    }
    blob.id = ++next_blob;
    if (in_submission) blobs_added.push_back(blob.id);
    blobs.push_back(std::move(blob));
  }

  // A structure created under handle `as` after `op` was recorded.
  bool Replaced(const ModelOp& op, uint32_t as) const {
    return op.recorded_at != 0 && structures[as].live && structures[as].created > op.recorded_at;
  }
  // The handles an operation names: its source (update, copy, serialization) and destination.
  bool NamesReplaced(const ModelOp& op) const {
    const bool has_src = (op.kind == ModelOp::kBuild && op.update) || op.kind == ModelOp::kCopy ||
                         op.kind == ModelOp::kSerializeDevice || op.kind == ModelOp::kSerializeHost;
    const bool has_dst = op.kind != ModelOp::kSerializeDevice && op.kind != ModelOp::kSerializeHost;
    return (has_src && Replaced(op, op.src)) || (has_dst && Replaced(op, op.dst));
  }
  void ApplyReplaced(const ModelOp& op) {
    switch (op.kind) {
      case ModelOp::kSerializeDevice:
      case ModelOp::kSerializeHost:
        for (ModelBlob& b : blobs) Invalidate(b);
        return;
      case ModelOp::kWriteProperties:
        slots[op.pool_query] = ModelSlot{op.dst, 0, op.query_type};
        return;
      default:
        if (!structures[op.dst].live) return;
        ModelHistory h;
        h.kind = ModelKind::kUnknown;
        h.reason = ModelUnknown::kStaleHandle;
        Write(op.dst, std::move(h));
        return;
    }
  }

  // Applies one operation in execution order. host_bytes: the host arrays as they are now.
  void Apply(const ModelOp& op, const std::vector<uint8_t> (&host_bytes)[kHostBlobs]) {
    if (NamesReplaced(op)) return ApplyReplaced(op);
    switch (op.kind) {
      case ModelOp::kBuild: {
        if (!structures[op.dst].live) return;  // destroyed before it executed: nothing to record
        ModelHistory h;
        if (op.unreadable) {
          h.kind = ModelKind::kUnknown;
          h.reason = ModelUnknown::kUnreadableBuild;
        } else {
          h.kind = ModelKind::kBuilt;
          h.params = op.params;
          if (op.update) {
            const ModelStructure& src = structures[op.src];
            if (src.live && src.history.kind == ModelKind::kBuilt && Repeats(src.history.params, op.params)) {
              h.params = src.history.params;
            }
          }
        }
        Write(op.dst, std::move(h));
        return;
      }
      case ModelOp::kCopy: {
        if (!structures[op.dst].live) return;
        const ModelStructure& src = structures[op.src];
        ModelHistory h;
        if (src.live && src.history.kind == ModelKind::kBuilt) {
          h.kind = ModelKind::kBuilt;
          h.params = src.history.params;
        } else {
          h.kind = ModelKind::kUnknown;
          h.reason = ModelUnknown::kCopiedFromUnknown;
        }
        Write(op.dst, std::move(h));
        return;
      }
      case ModelOp::kSerializeDevice: {
        if (!op.has_span) return;
        const ModelStructure& src = structures[op.src];
        ModelBlob blob;
        blob.device = true;
        blob.begin = op.begin;
        blob.end = op.end;
        if (src.live) {
          blob.history.kind = src.history.kind;
          blob.history.reason = src.history.reason;
          blob.history.params = src.history.params;
        }
        // Only a size read back for the source's current contents says how far the bytes reach: structures
        // there are clobbered; without it older serialized bytes up to the buffer's end are dropped, nothing
        // is clobbered on a guess.
        if (src.live && src.history.serialization_size) {
          if (*src.history.serialization_size < op.end - op.begin) blob.end = op.begin + *src.history.serialization_size;
          ClobberRange(blob.begin, blob.end, std::nullopt);
        } else {
          InvalidateDeviceBlobs(blob.begin, blob.end);
        }
        AddBlob(std::move(blob));
        return;
      }
      case ModelOp::kDeserializeDevice: {
        if (!structures[op.dst].live) return;
        ModelHistory h;
        h.kind = ModelKind::kUnknown;
        h.reason = ModelUnknown::kDeserializedDeviceBytes;
        Write(op.dst, std::move(h));
        return;
      }
      case ModelOp::kSerializeHost: {
        for (ModelBlob& b : blobs) {
          if (!b.device && b.host == op.blob) Invalidate(b);
        }
        ModelBlob blob;
        blob.host = op.blob;
        blob.bytes = host_bytes[op.blob];
        const ModelStructure& src = structures[op.src];
        if (src.live) {
          blob.history.kind = src.history.kind;
          blob.history.reason = src.history.reason;
          blob.history.params = src.history.params;
        }
        AddBlob(std::move(blob));
        return;
      }
      case ModelOp::kDeserializeHost: {
        if (!structures[op.dst].live) return;
        const ModelBlob* blob = LatestHostBlob(op.blob);
        if (blob && blob->bytes != host_bytes[op.blob]) blob = nullptr;
        ModelHistory h;
        if (blob && blob->history.kind == ModelKind::kBuilt) {
          h.kind = ModelKind::kBuilt;
          h.params = blob->history.params;
        } else {
          h.kind = ModelKind::kUnknown;
          h.reason = blob ? ModelUnknown::kCopiedFromUnknown : ModelUnknown::kDeserializedUnknownBytes;
        }
        Write(op.dst, std::move(h));
        return;
      }
      case ModelOp::kWriteProperties: {
        const ModelStructure& s = structures[op.dst];
        slots[op.pool_query] = ModelSlot{op.dst, s.live ? s.history.contents : 0, op.query_type};
        return;
      }
    }
  }

  // A command buffer the layer does not know was submitted: every live structure's history is unknown, every
  // serialized blob invalid.
  void ApplyLost() {
    for (uint32_t as = 0; as < kHandles; ++as) {
      if (!structures[as].live) continue;
      ModelHistory h;
      h.kind = ModelKind::kUnknown;
      h.reason = ModelUnknown::kLostOperations;
      h.contents = ++next_contents;
      structures[as].history = std::move(h);
      Touch(as);
    }
    for (ModelBlob& b : blobs) Invalidate(b);
  }

  // The app read back a serialization size for `as`'s current contents (contents: the ones it measured).
  void ReadBackSize(uint32_t as, uint64_t contents, uint64_t size) {
    ModelStructure& s = structures[as];
    if (!s.live || contents == 0 || s.history.contents != contents) return;
    s.history.serialization_size = size;
    Touch(as);
  }

  void Destroy(uint32_t as) {
    structures[as] = ModelStructure{};
  }
  void Create(uint32_t as, uint64_t begin, uint64_t end) {
    structures[as] = ModelStructure{};
    structures[as].live = true;
    structures[as].created = ++clock;
    structures[as].begin = begin;
    structures[as].end = end;
  }

  // Starting a submission: `before` keeps this state for an undo.
  void BeginSubmission() {
    in_submission = true;
    blobs_added.clear();
    blobs_invalidated.clear();
    for (bool& c : changed_after) c = false;
  }
  void EndApply() { in_submission = false; }
  // The submission did not happen: every structure a host operation did not change since gets its history
  // before the submission back; blobs added are dropped, blobs invalidated valid again; slots as before.
  void Undo(const Model& before) {
    for (uint32_t as = 0; as < kHandles; ++as) {
      if (!changed_after[as]) structures[as].history = before.structures[as].history;
    }
    for (uint32_t id : blobs_added) {
      for (auto it = blobs.begin(); it != blobs.end(); ++it) {
        if (it->id == id) {
          blobs.erase(it);
          break;
        }
      }
    }
    for (uint32_t id : blobs_invalidated) {
      for (ModelBlob& b : blobs) {
        if (b.id == id) b.valid = true;
      }
    }
    slots = before.slots;
  }
};

}  // namespace asval::fuzz
