#include "traced_tops.h"

#include <algorithm>
#include <array>
#include <memory>
#include <mutex>

#include "buffer_descriptors.h"

namespace asval {

namespace {

bool HasTraces(const std::vector<InFlightBatch>& staged, std::size_t first) {
  for (std::size_t k = first; k < staged.size(); ++k) {
    for (const std::shared_ptr<const RecordedOps>& recorded : staged[k].recorded) {
      if (recorded && recorded->batch.traced().size() != 0) return true;
    }
  }
  return false;
}

// The structures the submission's commands write (their destinations), sorted: a trace before such a write may have
// read an older build, one after it reads this write; neither is known here. Made once per submission, and only when
// a traced top level is otherwise certain (rare: a top level built in an earlier submission and written again here).
class WrittenIn {
 public:
  WrittenIn(const std::vector<InFlightBatch>& staged, std::size_t first) : staged_(staged), first_(first) {}
  bool Names(VkAccelerationStructureKHR as) {
    if (!made_) Make();
    return std::binary_search(written_.begin(), written_.end(), as);
  }

 private:
  void Make() {
    made_ = true;
    written_.clear();
    for (std::size_t k = first_; k < staged_.size(); ++k) {
      for (const std::shared_ptr<const RecordedOps>& recorded : staged_[k].recorded) {
        if (!recorded) continue;
        for (const AsOp& op : recorded->batch.ops()) {
          if (op.dst && op.kind != OpKind::kTrace && op.kind != OpKind::kWriteProperties) written_.push_back(op.dst);
        }
      }
    }
    std::sort(written_.begin(), written_.end());
  }

  const std::vector<InFlightBatch>& staged_;
  std::size_t first_;
  bool made_ = false;
  // This thread's, kept with its capacity.
  static thread_local std::vector<VkAccelerationStructureKHR> written_;
};
thread_local std::vector<VkAccelerationStructureKHR> WrittenIn::written_;

// The bindings a batch's traces read already: a frame's dispatches bind the same set again and again, and each
// (source, set or structure or address, binding or serial or count) names the same structures (sets and descriptor
// bytes are read now) and so the same top levels. A few kept, the oldest replaced.
class SeenBindings {
 public:
  // Whether `b` was seen; remembers it.
  bool Seen(const TracedBinding& b) {
    Key key{b.source, 0, 0};
    switch (b.source) {
      case TracedSource::kSet:
        key.object = reinterpret_cast<uint64_t>(b.set);
        key.detail = b.binding;
        break;
      case TracedSource::kPushed:
        key.object = reinterpret_cast<uint64_t>(b.pushed);
        key.detail = b.pushed_serial;
        break;
      case TracedSource::kBuffer:
        key.object = b.descriptor_address;
        key.detail = b.descriptor_count;
        break;
      default:
        return true;  // reads nothing the layer follows
    }
    for (std::size_t k = 0; k < count_; ++k) {
      if (keys_[k] == key) return true;
    }
    keys_[next_] = key;
    next_ = (next_ + 1) % keys_.size();
    if (count_ < keys_.size()) ++count_;
    return false;
  }

 private:
  struct Key {
    TracedSource source;
    uint64_t object, detail;
    bool operator==(const Key& o) const { return source == o.source && object == o.object && detail == o.detail; }
  };
  std::array<Key, 8> keys_{};
  std::size_t next_ = 0, count_ = 0;
};

}  // namespace

void NoteTracedTops(const DeviceState& state, uint64_t submission, std::vector<InFlightBatch>& staged,
                    std::size_t first) {
  if (!state.history_tracked || !HasTraces(staged, first)) return;
  const std::unique_lock<std::mutex> lock = state.history.store.Lock();
  const HistoryStore& store = state.history.store;
  WrittenIn written(staged, first);
  for (std::size_t k = first; k < staged.size(); ++k) {
    InFlightBatch& batch = staged[k];
    SeenBindings seen;
    for (const std::shared_ptr<const RecordedOps>& recorded : batch.recorded) {
      if (!recorded || recorded->batch.traced().size() == 0) continue;
      for (const AsOp& op : recorded->batch.ops()) {
        if (op.kind != OpKind::kTrace) continue;
        const auto read = [&](VkAccelerationStructureKHR as, uint64_t serial) {
          if (!as || serial == 0) return;
          const std::optional<std::shared_ptr<const AccelerationStructureState>> live =
              state.acceleration_structures.find(as);
          if (!live || !*live || (*live)->serial != serial) return;
          const AsHistory* h = store.Find(as);
          if (!h || h->kind != HistoryKind::kBuilt || !h->build || !h->activity ||
              h->build->type == VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR) {
            return;
          }
          const uint64_t built_in = h->activity->submission();
          if (built_in == 0 || built_in == submission) return;
          std::shared_ptr<const ReferencedStructures> references = h->activity->references();
          if (!references || references->structures.empty()) return;
          const bool kept = std::any_of(batch.traced_tops.begin(), batch.traced_tops.end(),
                                        [&](const InFlightBatch::TracedTop& t) { return t.references == references; });
          if (kept || written.Names(as)) return;
          batch.traced_tops.push_back({as, &op, std::move(references)});
        };
        const TracedBinding* bindings = recorded->batch.traced().begin() + op.first_geometry;
        for (uint32_t i = 0; i < op.geometry_count; ++i) {
          const TracedBinding& b = bindings[i];
          if (seen.Seen(b)) continue;
          if (b.source == TracedSource::kPushed) read(b.pushed, b.pushed_serial);
          if (b.source == TracedSource::kBuffer) {
            ForEachBufferDescriptor(state, b.descriptor_address, b.descriptor_count,
                                    [&](BufferDescriptor what, const AccelerationStructureState* s) {
                                      if (what == BufferDescriptor::kStructure) read(s->handle, s->serial);
                                    });
          }
          if (b.source == TracedSource::kSet) {
            state.ray_bindings.ForEachIn(b.set, b.binding, [&](const DescribedStructure& d) { read(d.as, d.serial); });
          }
        }
      }
    }
  }
}

}  // namespace asval
