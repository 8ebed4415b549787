#include "history_apply.h"

#include <algorithm>
#include <cstring>
#include <new>

#include "failure_injection.h"
#include "nv_structures.h"
#include "structure_memory.h"

namespace asval {

namespace {

// GeometryRecord's ==, without a branch per member: every applied build compares its geometries with the
// snapshot it may share.
bool SameGeometry(const GeometryRecord& a, const GeometryRecord& b) {
  const uint32_t differ = (a.type ^ b.type) | (a.flags ^ b.flags) | (a.vertex_format ^ b.vertex_format) |
                          (a.index_type ^ b.index_type) | (a.max_vertex ^ b.max_vertex) |
                          (a.primitive_count ^ b.primitive_count) | (a.has_transform ^ b.has_transform) |
                          (a.primitive_count_known ^ b.primitive_count_known);
  return differ == 0;
}

bool SameGeometries(const std::vector<GeometryRecord>& snapshot, const GeometryRecord* geometries, uint32_t count) {
  if (snapshot.size() != count) return false;
  for (uint32_t j = 0; j < count; ++j) {
    if (!SameGeometry(snapshot[j], geometries[j])) return false;
  }
  return true;
}

// Builds with identical parameters share one snapshot, so that a structure rebuilt or updated every frame
// costs no allocation (the snapshot's origin then names the first of the identical builds).
bool SameParameters(const BuildSnapshot& snapshot, const OpBatch& batch, const AsOp& op) {
  return snapshot.flags == op.flags && snapshot.type == op.type &&
         SameGeometries(snapshot.geometries, batch.GeometriesOf(op), op.geometry_count);
}

std::shared_ptr<const BuildSnapshot> MakeSnapshot(const OpBatch& batch, const AsOp& op) {
  auto snapshot = std::make_shared<BuildSnapshot>();
  snapshot->flags = op.flags;
  snapshot->type = op.type;
  const GeometryRecord* geometries = batch.GeometriesOf(op);
  snapshot->geometries.assign(geometries, geometries + op.geometry_count);
  snapshot->origin = op.origin;
  return snapshot;
}

// For an update: the source's snapshot when the update repeats it (primitive counts an indirect update
// does not know are taken as repeated), else the update's own parameters.
std::shared_ptr<const BuildSnapshot> UpdateSnapshot(const AsHistory& src, const OpBatch& batch, const AsOp& op) {
  if (src.kind == HistoryKind::kBuilt && src.build) {
    const BuildSnapshot& s = *src.build;
    if (op.origin.command != OpCommand::kCmdBuildIndirect) {
      // Every primitive count known (only indirect builds keep theirs on the device): a plain comparison.
      if (SameParameters(s, batch, op)) return src.build;
      return MakeSnapshot(batch, op);
    }
    bool same = s.flags == op.flags && s.type == op.type && s.geometries.size() == op.geometry_count;
    const GeometryRecord* geometries = batch.GeometriesOf(op);
    for (uint32_t j = 0; same && j < op.geometry_count; ++j) {
      GeometryRecord g = geometries[j];
      if (!g.primitive_count_known) {
        g.primitive_count = s.geometries[j].primitive_count;
        g.primitive_count_known = s.geometries[j].primitive_count_known;
      }
      same = g == s.geometries[j];
    }
    if (same) return src.build;
  }
  return MakeSnapshot(batch, op);
}

// A structure an operation writes: its record (kNoRecord when it has none yet) and the history it gets.
struct Written {
  uint32_t record = HistoryStore::kNoRecord;
  AsHistory history;
};

// The written structure's new record, with its span, a fresh generation and no clobber; nullopt for a handle
// that is not a live structure (destroyed before the command buffer was submitted: an invalid submission whose
// record would otherwise outlive the structure and greet a new one with the same handle value). A structure's
// span never changes while it lives (its buffer's binding is immutable), so a known one is reused rather than
// looked up again in the shadow maps; records end when structures are destroyed, so one with a record lives.
std::optional<Written> Fresh(const DeviceState& state, HistoryStore& store, VkAccelerationStructureKHR as) {
  std::optional<Written> w(std::in_place);
  w->record = store.RecordOf(as);
  if (w->record != HistoryStore::kNoRecord && store.HistoryAt(w->record).span.memory != VK_NULL_HANDLE) {
    w->history.span = store.HistoryAt(w->record).span;
  } else if (w->record == HistoryStore::kNoRecord && !state.acceleration_structures.contains(as) &&
             !FindNvByKey(state, as)) {
    return std::nullopt;
  } else if (std::optional<MemorySpan> span = AccelerationStructureSpan(state, as)) {
    w->history.span = *span;
  }
  w->history.generation = store.NextGeneration();
  return w;
}

// A write of `span` by `op` leaves every other structure there with contents that are not what was built, and
// any serialized bytes there modified. writer_record: the written structure's record (its span is `span`), whose
// store remembers whether anything overlaps it; kNoRecord for serialized bytes.
void ClobberOverlapping(HistoryStore& store, const MemorySpan& span, VkAccelerationStructureKHR writer,
                        uint32_t writer_record, const AsOp& op, Transaction* txn) {
  if (span.memory == VK_NULL_HANDLE) return;
  if (store.has_blobs()) store.InvalidateBlobsOverlapping(span, txn);
  if (writer_record != HistoryStore::kNoRecord && store.Alone(writer_record)) return;  // most structures
  // Collected first: Set() may re-index while the span index is being walked otherwise.
  VkAccelerationStructureKHR hits[16];
  std::size_t count = 0;
  bool more = true;
  while (more) {
    more = false;
    count = 0;
    const auto collect = [&](VkAccelerationStructureKHR as) {
      const AsHistory* h = store.Find(as);
      if (!h || h->kind == HistoryKind::kNeverBuilt || h->clobbered) return;
      if (count < 16) {
        hits[count++] = as;
      } else {
        more = true;
      }
    };
    if (writer_record != HistoryStore::kNoRecord) {
      store.ForEachOverlappingRecord(writer_record, writer, collect);
    } else {
      store.ForEachOverlapping(span, writer, collect);
    }
    for (std::size_t i = 0; i < count; ++i) {
      AsHistory h = *store.Find(hits[i]);
      h.clobbered = Clobber{op.origin, writer};
      store.Set(hits[i], std::move(h), txn);
    }
  }
}

void SetWritten(HistoryStore& store, VkAccelerationStructureKHR dst, Written& written, const AsOp& op,
                Transaction* txn) {
  const MemorySpan span = written.history.span;
  if (written.history.kind == HistoryKind::kUnknown) {
    store.structures_made_unknown.fetch_add(1, std::memory_order_relaxed);
  }
  uint32_t record = written.record;
  if (record == HistoryStore::kNoRecord) {
    record = store.Set(dst, std::move(written.history), txn);
  } else {
    store.SetAt(record, dst, std::move(written.history), txn);
  }
  ClobberOverlapping(store, span, dst, record, op, txn);
}

// An indirect build's captured range infos, judged when its submission completes. An update takes its source's
// last build now, in submission order (the store holds the source as it is before the update is applied): a
// later submission may rebuild the source before this one completes. Sharing the snapshot allocates nothing.
IndirectRangeCheck IndirectCheck(const HistoryStore& store, const AsOp& op, CaptureLog* log) {
  IndirectRangeCheck check{log->shared_from_this(), op.capture_info, op.origin, op.dst};
  if (op.is_update()) {
    check.src = op.src;
    const AsHistory* src = store.Find(op.src);
    if (src && src->kind == HistoryKind::kBuilt) check.source = src->build;
  }
  return check;
}

// A captured build's activity, filled when its submission completes; an update's comparison with its source's.
// The same capture read twice by one submission (a command buffer submitted twice in one call, a secondary executed
// by two of its primaries; a secondary executed twice by one primary reads a saved copy the first time, unless the
// copy could not be made: capture_saves.h) holds the bytes of the last execution only: both are unknown.
std::shared_ptr<BuildActivity> CapturedActivity(const DeviceState& state, const HistoryStore& store, const AsOp& op,
                                                SubmissionCaptures& captures) {
  CaptureLog* log = op.capture_log;
  auto node = std::make_shared<BuildActivity>(log->shared_from_this(), op.capture_info, op.origin, op.dst);
  node->SetSubmission(captures.id);
  const auto key = std::make_pair(static_cast<const CaptureLog*>(log), op.capture_info);
  auto [it, first] = captures.claimed.emplace(key, node.get());
  if (!first) {
    it->second->MarkUnknown();
    node->MarkUnknown();
  }
  bool known_log = false;
  for (const std::shared_ptr<CaptureLog>& held : captures.logs) known_log |= held.get() == log;
  if (!known_log) captures.logs.push_back(log->shared_from_this());
  captures.fills.push_back(node);
  if (op.origin.command == OpCommand::kCmdBuildIndirect) {
    captures.indirect_checks.push_back(IndirectCheck(store, op, log));
  }
  // An indirect build's instances are known where the layer's dispatch read them (CapturedInfo::indirect_geometry).
  const bool instances_captured =
      op.origin.command != OpCommand::kCmdBuildIndirect ||
      (op.capture_info < log->infos.size() && log->infos[op.capture_info].indirect_geometry);
  if (op.type == VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR && instances_captured) {
    InstanceReferenceCheck check;
    check.log = log->shared_from_this();
    check.info = op.capture_info;
    check.live = state.live_structure_addresses.Get(
        state.acceleration_structures, state.structure_storage_changes.Read(),
        [&](const auto& structure) { return StorageOfStructure(state, structure); },
        state.failures().structures_incomplete.load(std::memory_order_relaxed));
    if (state.instance_activity_snapshots) {
      check.activities.reserve(check.live->structures.size());
      for (const auto& structure : check.live->structures) {
        const AsHistory* h = store.Find(structure->handle);
        const bool built = h && h->kind == HistoryKind::kBuilt && !h->clobbered;
        check.activities.push_back(built ? h->activity : nullptr);
      }
    }
    check.build = op.origin;
    check.dst = op.dst;
    check.activity = node;
    captures.instance_checks.push_back(std::move(check));
  }
  if (op.is_update()) captures.comparisons.push_back(ComparisonWithSource(store, op, node));
  return node;
}

// A host build's activity: its inputs were copied when it was called and it has run, so the record is filled now,
// before the history that holds it is published (under the store's lock: no reader sees it pending).
std::shared_ptr<BuildActivity> HostActivity(const AsOp& op) {
  auto node = std::make_shared<BuildActivity>(op.capture_log->shared_from_this(), op.capture_info, op.origin, op.dst);
  node->Fill();
  return node;
}

// The record whose snapshot a build or update of dst may share: dst's own (a build), or the source's (an update; most
// are in place: the source's record is the destination's, already found). kNoRecord when it has none.
uint32_t BaseRecord(const HistoryStore& store, const AsOp& op, uint32_t dst_record) {
  return !op.is_update() || op.src == op.dst ? dst_record : store.RecordOf(op.src);
}

// What this operation left last time its batch was applied, when it is still there to share: its own parameters
// (made from them, or compared equal), so finding it again in the source (update) or in dst (build) is finding
// the same parameters. Null when it must compare.
[[gnu::always_inline]] inline const std::shared_ptr<const BuildSnapshot>* RememberedSnapshot(const HistoryStore& store,
                                                                                             const OpBatch& batch,
                                                                                             const AsOp& op,
                                                                                             uint32_t dst_record) {
  std::shared_ptr<const BuildSnapshot>* memo = batch.AppliedSnapshot(op);
  if (!memo || !*memo) return nullptr;
  const uint32_t base_record = BaseRecord(store, op, dst_record);
  if (base_record == HistoryStore::kNoRecord) return nullptr;
  const AsHistory& base = store.HistoryAt(base_record);
  return base.build == *memo && (!op.is_update() || base.kind == HistoryKind::kBuilt) ? memo : nullptr;
}

// The parameters a build or update leaves in dst (dst_record: dst's record, kNoRecord when it has none): shared
// with the source's or the previous build's when they are the same, so that steady frames allocate nothing.
// Returned by reference, so that finding the same snapshot again copies no shared pointer: to the batch's memo of
// this operation (which a rewrite of the histories leaves alone), or to `storage` for batches without one.
const std::shared_ptr<const BuildSnapshot>& BuiltSnapshot(const HistoryStore& store, const OpBatch& batch,
                                                          const AsOp& op, uint32_t dst_record,
                                                          std::shared_ptr<const BuildSnapshot>& storage) {
  if (const std::shared_ptr<const BuildSnapshot>* remembered = RememberedSnapshot(store, batch, op, dst_record)) {
    return *remembered;
  }
  const uint32_t base_record = BaseRecord(store, op, dst_record);
  const AsHistory* base = base_record != HistoryStore::kNoRecord ? &store.HistoryAt(base_record) : nullptr;
  std::shared_ptr<const BuildSnapshot>* memo = batch.AppliedSnapshot(op);
  std::shared_ptr<const BuildSnapshot>& built = memo ? *memo : storage;
  if (op.is_update()) {
    built = base ? UpdateSnapshot(*base, batch, op) : MakeSnapshot(batch, op);
  } else {
    built = base && base->build && SameParameters(*base->build, batch, op) ? base->build : MakeSnapshot(batch, op);
  }
  return built;
}

// The activity a build leaves in dst: filled now (host builds) or when the submission completes (captured device
// builds); null when not captured. Reads the histories as they are before the build (its source's activity, the
// instances' structures').
std::shared_ptr<BuildActivity> BuiltActivity(const DeviceState& state, const HistoryStore& store, const AsOp& op,
                                             SubmissionCaptures* captures) {
  if (!op.capture_log) return nullptr;
  if (op.origin.command == OpCommand::kHostBuild) return HostActivity(op);
  return captures ? CapturedActivity(state, store, op, *captures) : nullptr;
}

void ApplyBuild(const DeviceState& state, HistoryStore& store, const OpBatch& batch, const AsOp& op, Transaction* txn,
                SubmissionCaptures* captures) {
  const uint32_t record = store.RecordOf(op.dst);
  if (record != HistoryStore::kNoRecord && !op.geometries_unreadable &&
      store.HistoryAt(record).span.memory != VK_NULL_HANDLE) {
    // The common case, a structure built before: its record is rewritten in place, its span known and unchanged.
    std::shared_ptr<const BuildSnapshot> storage;
    const std::shared_ptr<const BuildSnapshot>* remembered = RememberedSnapshot(store, batch, op, record);
    const std::shared_ptr<const BuildSnapshot>& build =
        remembered ? *remembered : BuiltSnapshot(store, batch, op, record, storage);
    std::shared_ptr<BuildActivity> activity = BuiltActivity(state, store, op, captures);
    AsHistory& h = store.Rewrite(record, op.dst, txn, build);
    h.kind = HistoryKind::kBuilt;
    if (activity) h.activity = std::move(activity);
    // Most structures own their bytes, and most devices hold no serialized bytes the layer tracks.
    if (store.has_blobs() || !store.Alone(record)) {
      const MemorySpan span = h.span;
      ClobberOverlapping(store, span, op.dst, record, op, txn);
    }
    return;
  }
  std::optional<Written> fresh = Fresh(state, store, op.dst);
  if (!fresh) return;
  AsHistory& h = fresh->history;
  if (op.geometries_unreadable) {
    h.kind = HistoryKind::kUnknown;
    h.unknown_reason = UnknownReason::kUnreadableBuild;
    SetWritten(store, op.dst, *fresh, op, txn);
    return;
  }
  h.kind = HistoryKind::kBuilt;
  std::shared_ptr<const BuildSnapshot> storage;
  h.build = BuiltSnapshot(store, batch, op, fresh->record, storage);
  h.activity = BuiltActivity(state, store, op, captures);
  SetWritten(store, op.dst, *fresh, op, txn);
}

void ApplyCopy(const DeviceState& state, HistoryStore& store, const AsOp& op, Transaction* txn) {
  const AsHistory src = store.Get(op.src);
  std::optional<Written> fresh = Fresh(state, store, op.dst);
  if (!fresh) return;
  AsHistory& h = fresh->history;
  if (src.kind == HistoryKind::kBuilt) {
    h.kind = HistoryKind::kBuilt;
    h.build = src.build;
    h.activity = src.activity;  // a clone or compaction keeps every primitive as it was
  } else {
    // Copying a structure never built is its own error (src-04963); what lands in dst is unknown either way.
    h.kind = HistoryKind::kUnknown;
    h.unknown_reason = UnknownReason::kCopiedFromUnknown;
  }
  SetWritten(store, op.dst, *fresh, op, txn);
}

// Whether one submission already reads capture (log, blob) of a serialization or deserialization: the device then
// writes its bytes twice before the layer reads them (a command buffer submitted twice in one call, a secondary
// executed by two of its primaries), so that both readers are unknown. Submissions serialize rarely: a scan.
bool ClaimBlob(SubmissionCaptures& captures, CaptureLog* log, uint32_t blob) {
  bool first = true;
  for (SerializeCapture& s : captures.serializes) {
    if (s.log.get() == log && s.blob == blob) s.read_twice = true, first = false;
  }
  for (DeserializeCheck& d : captures.deserializes) {
    if (d.log.get() == log && d.blob == blob) d.read_twice = true, first = false;
  }
  bool known_log = false;
  for (const std::shared_ptr<CaptureLog>& held : captures.logs) known_log |= held.get() == log;
  if (!known_log) captures.logs.push_back(log->shared_from_this());
  return first;
}

void ApplySerialize(HistoryStore& store, const AsOp& op, Transaction* txn, SubmissionCaptures* captures) {
  const AsHistory src = store.Get(op.src);
  SerializedBlob blob;
  blob.history.kind = src.kind;
  blob.history.unknown_reason = src.unknown_reason;
  blob.history.build = src.build;
  // The serialized structure's primitive activity travels with its bytes as with a clone: a deserialization
  // recreates the structure exactly.
  blob.history.activity = src.activity;
  if (op.memory.host_address) {
    store.InvalidateHostBlob(op.memory.host_address, txn);
    blob.host_address = op.memory.host_address;
    blob.host_size = SerializedHostSize(op.memory.host_address);
    blob.host_hash = HashBytes(op.memory.host_address, blob.host_size);
    store.AddBlob(std::move(blob), txn);
    return;
  }
  if (op.memory.span.memory == VK_NULL_HANDLE) return;  // bytes in memory the layer does not know
  const bool size_known = src.serialization_size_generation != 0 && src.serialization_size_generation == src.generation;
  blob.span = op.memory.span;
  if (size_known && src.serialization_size < blob.span.end - blob.span.begin) {
    blob.span.end = blob.span.begin + src.serialization_size;
  }
  // The bytes written: exactly known only with the serialization size. Without it, older serialized bytes
  // up to the buffer's end are taken as overwritten (they then restore nothing: safe), but no structure is
  // reported as clobbered on a guess.
  if (size_known) {
    ClobberOverlapping(store, blob.span, VK_NULL_HANDLE, HistoryStore::kNoRecord, op, txn);
  } else {
    store.InvalidateBlobsOverlapping(blob.span, txn);
  }
  // Captured after it executed (issue 12): the content is hashed when this submission completes, and a later
  // deserialization from here is verified against it.
  blob.device_address = op.memory.device_address;
  if (captures && op.capture_log) {
    blob.content = std::make_shared<SerializedContent>();
    SerializeCapture capture;
    capture.log = op.capture_log->shared_from_this();
    capture.blob = op.capture_info;
    capture.content = blob.content;
    capture.read_twice = !ClaimBlob(*captures, op.capture_log, op.capture_info);
    captures->serializes.push_back(std::move(capture));
  }
  store.AddBlob(std::move(blob), txn);
}

void ApplyDeserialize(const DeviceState& state, HistoryStore& store, const AsOp& op, Transaction* txn,
                      SubmissionCaptures* captures) {
  std::optional<Written> fresh = Fresh(state, store, op.dst);
  if (!fresh) return;
  AsHistory& h = fresh->history;
  const SerializedBlob* blob = nullptr;
  // Host bytes are trusted to be what the layer saw serialized by their hash, now. Device memory may have been
  // rewritten by commands the layer does not follow (vkCmdCopyBuffer, vkCmdUpdateBuffer, vkCmdFillBuffer, copies
  // from images, shader writes), by the host through a mapping, or freed and reallocated: its bytes are verified
  // by content when the capture copied them, once this submission completes (DeserializeCheck); until then the
  // history is unknown, so that an update submitted before the completion is processed is skipped, never guessed.
  if (op.memory.host_address) {
    const SerializedBlob* candidate = store.FindHostBlob(op.memory.host_address);
    if (candidate && SerializedHostSize(op.memory.host_address) == candidate->host_size &&
        HashBytes(op.memory.host_address, candidate->host_size) == candidate->host_hash) {
      blob = candidate;
    }
  }
  if (blob && blob->history.kind == HistoryKind::kBuilt) {
    h.kind = HistoryKind::kBuilt;
    h.build = blob->history.build;
    h.activity = blob->history.activity;
  } else {
    h.kind = HistoryKind::kUnknown;
    h.unknown_reason = blob                     ? UnknownReason::kCopiedFromUnknown
                       : op.memory.host_address ? UnknownReason::kDeserializedUnknownBytes
                                                : UnknownReason::kDeserializedDeviceBytes;
  }
  if (!op.memory.host_address && captures && op.capture_log) {
    // The serialization the bytes should hold: the latest one there that no tracked write overlapped since, in
    // submission order (what executes before this deserialization). Only a built structure's history is worth
    // restoring.
    const SerializedBlob* device_blob = store.FindDeviceBlob(op.memory.span);
    const bool claimed_first = ClaimBlob(*captures, op.capture_log, op.capture_info);
    if (device_blob && device_blob->content && device_blob->history.kind == HistoryKind::kBuilt) {
      DeserializeCheck check;
      check.log = op.capture_log->shared_from_this();
      check.blob = op.capture_info;
      check.expected = device_blob->content;
      check.build = device_blob->history.build;
      check.activity = device_blob->history.activity;
      check.dst = op.dst;
      check.generation = h.generation;
      check.read_twice = !claimed_first;
      captures->deserializes.push_back(std::move(check));
    }
  }
  SetWritten(store, op.dst, *fresh, op, txn);
}

void ApplyWriteProperties(HistoryStore& store, const AsOp& op, Transaction* txn) {
  if (!op.query_pool) return;  // host writes hand their values over at once (RecordSerializationSize)
  const AsHistory* h = store.Find(op.dst);
  store.SetSlot(op.query_pool, op.query, QuerySlot{op.dst, h ? h->generation : 0, op.query_type}, txn);
}

// A device command whose handle now names a structure created after the recording (the one it named was destroyed,
// or it named none): the command buffer is invalid (reported by layer/checks/recorded_objects.h, or by the Khronos
// layer), and what the command does with the stale handle is not defined. One load while no structure was created
// after the recording.
bool NamesReplacedStructure(const DeviceState& state, const AsOp& op) {
  const uint64_t recorded_at = op.origin.recorded_at;
  if (recorded_at == 0 || op.kind == OpKind::kTrace || state.lifetimes.last_structure_created() <= recorded_at) {
    return false;
  }
  const auto replaced = [&](VkAccelerationStructureKHR as) {
    if (!as) return false;
    if (IsNvCommand(op.origin.command)) {
      const std::shared_ptr<const NvStructureState> nv = FindNvByKey(state, as);
      return nv && nv->serial > recorded_at;
    }
    const std::optional<std::shared_ptr<const AccelerationStructureState>> now = state.acceleration_structures.find(as);
    return now && *now && (*now)->serial > recorded_at;
  };
  return replaced(op.src) || replaced(op.dst);
}

// Never guessed: the structure under the destination handle (the newer one, or one written from it) becomes unknown,
// a property query of it names no contents, and a serialization may have written any serialized bytes.
void ApplyOnReplaced(const DeviceState& state, HistoryStore& store, const AsOp& op, Transaction* txn) {
  switch (op.kind) {
    case OpKind::kBuild:
    case OpKind::kCopy:
    case OpKind::kDeserialize:
      if (std::optional<Written> fresh = Fresh(state, store, op.dst)) {
        fresh->history.kind = HistoryKind::kUnknown;
        fresh->history.unknown_reason = UnknownReason::kStaleHandle;
        SetWritten(store, op.dst, *fresh, op, txn);  // what else lies in its memory is clobbered, as by any write
      }
      return;
    case OpKind::kWriteProperties:
      if (op.query_pool) store.SetSlot(op.query_pool, op.query, QuerySlot{op.dst, 0, op.query_type}, txn);
      return;
    case OpKind::kSerialize:
      store.InvalidateAllBlobs(txn);
      return;
    case OpKind::kTrace:
      return;
  }
}

}  // namespace

std::optional<MemorySpan> AccelerationStructureSpan(const DeviceState& state, VkAccelerationStructureKHR as) {
  if (const std::optional<StructureMemory> memory = MemoryOfStructure(state, as)) return memory->Span();
  // VK_NV_ray_tracing: memory bound to the structure itself.
  if (const std::shared_ptr<const NvStructureState> nv = FindNvByKey(state, as)) return NvStructureSpan(*nv);
  return std::nullopt;
}

void ApplyUnknownCommandBuffer(const DeviceState& state, HistoryStore& store, Transaction* txn) {
  // The structures that exist now: one created later cannot have been written by this command buffer.
  const auto live = state.acceleration_structures.snapshot();
  for (const auto& [as, record] : live) {
    std::optional<Written> fresh = Fresh(state, store, as);
    if (!fresh) continue;
    fresh->history.kind = HistoryKind::kUnknown;
    fresh->history.unknown_reason = UnknownReason::kLostOperations;
    store.Set(as, std::move(fresh->history), txn);
    store.structures_made_unknown.fetch_add(1, std::memory_order_relaxed);  // once it is
  }
  if (state.features.nv_ray_tracing) {
    for (const auto& [nv, record] : state.nv_structures.snapshot()) {
      if (!record || record->shares_key) continue;
      std::optional<Written> fresh = Fresh(state, store, NvHistoryKey(nv));
      if (!fresh) continue;
      fresh->history.kind = HistoryKind::kUnknown;
      fresh->history.unknown_reason = UnknownReason::kLostOperations;
      store.Set(NvHistoryKey(nv), std::move(fresh->history), txn);
      store.structures_made_unknown.fetch_add(1, std::memory_order_relaxed);
    }
  }
  // Any serialized bytes may have been overwritten.
  store.InvalidateAllBlobs(txn);
}

void MakeAllUnknownAfterFailure(const DeviceState& state, HistoryStore& store) {
  FailureCounters& failures = state.failures();
  const uint64_t before = store.structures_made_unknown.load(std::memory_order_relaxed);
  try {
    ApplyUnknownCommandBuffer(state, store, nullptr);
  } catch (const std::bad_alloc&) {
    failures.allocation_failures.fetch_add(1, std::memory_order_relaxed);
  }
  failures.structures_made_unknown.fetch_add(store.structures_made_unknown.load(std::memory_order_relaxed) - before,
                                             std::memory_order_relaxed);
}

void ApplyOp(const DeviceState& state, HistoryStore& store, const OpBatch& batch, const AsOp& op, Transaction* txn,
             SubmissionCaptures* captures) {
  InjectBadAlloc(FailSite::kApply);  // the test hook: as if this operation's first allocation failed
  if (NamesReplacedStructure(state, op)) return ApplyOnReplaced(state, store, op, txn);
  switch (op.kind) {
    case OpKind::kBuild:
      ApplyBuild(state, store, batch, op, txn, captures);
      break;
    case OpKind::kCopy:
      ApplyCopy(state, store, op, txn);
      break;
    case OpKind::kSerialize:
      ApplySerialize(store, op, txn, captures);
      break;
    case OpKind::kDeserialize:
      ApplyDeserialize(state, store, op, txn, captures);
      break;
    case OpKind::kWriteProperties:
      ApplyWriteProperties(store, op, txn);
      break;
    case OpKind::kTrace:
      break;  // reads structures only (judged before: layer/checks/traced_structures.h)
  }
}

void RememberReferencedBuilds(const HistoryStore& store, ReferencedStructures& references) {
  std::sort(
      references.structures.begin(), references.structures.end(),
      [](const ReferencedStructures::Referenced& a, const ReferencedStructures::Referenced& b) { return a.as < b.as; });
  const std::unique_lock<std::mutex> lock = store.Lock();
  for (ReferencedStructures::Referenced& r : references.structures) {
    const AsHistory* h = store.Find(r.as);
    if (!h || h->kind != HistoryKind::kBuilt) continue;  // not known: no rebuild is judged against it
    r.build = h->build;
    r.generation = h->generation;
  }
}

void RecordSerializationSize(HistoryStore& store, VkAccelerationStructureKHR as, uint64_t generation, uint64_t size) {
  const AsHistory* current = store.Find(as);
  if (!current || current->generation != generation || generation == 0) return;  // rebuilt since: stale
  AsHistory h = *current;
  h.serialization_size = size;
  h.serialization_size_generation = generation;
  store.Set(as, std::move(h), nullptr);
}

ActivityComparison ComparisonWithSource(const HistoryStore& store, const AsOp& op,
                                        std::shared_ptr<BuildActivity> after) {
  ActivityComparison comparison;
  if (const AsHistory* src = store.Find(op.src)) {
    comparison.before = src->activity;
    if (src->build) comparison.source_build = src->build->origin;
  }
  comparison.after = std::move(after);
  comparison.update = op.origin;
  comparison.src = op.src;
  comparison.dst = op.dst;
  return comparison;
}

bool RestoreDeserializedHistory(HistoryStore& store, const DeserializeCheck& check) {
  const AsHistory* current = store.Find(check.dst);
  // Only the record the deserialization left: a later build, copy or deserialization of dst (or its destruction)
  // changed the generation; a later write over its memory set `clobbered` without changing it, and may still be
  // undone by a submission in flight on another thread, whose undo would then leave this record alone.
  if (!current || current->generation != check.generation || current->kind != HistoryKind::kUnknown ||
      current->unknown_reason != UnknownReason::kDeserializedDeviceBytes || current->clobbered || !check.build) {
    return false;
  }
  AsHistory h = *current;  // same contents, same generation (a serialization size read back stays attached)
  h.kind = HistoryKind::kBuilt;
  h.unknown_reason = UnknownReason::kNone;
  h.build = check.build;
  h.activity = check.activity;
  store.Set(check.dst, std::move(h), nullptr);
  return true;
}

uint64_t SerializedHostSize(const void* data) {
  uint64_t size = 0;
  std::memcpy(&size, static_cast<const unsigned char*>(data) + 2 * VK_UUID_SIZE, sizeof(size));
  return size;
}

}  // namespace asval
