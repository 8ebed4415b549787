#include "lifetime.h"

#include <fmt/format.h>

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "buffer_descriptors.h"
#include "buffer_lookup.h"
#include "structure_memory.h"
#include "traced_structures.h"

namespace asval {

namespace {

constexpr const char kStructureInUse[] = "VUID-vkDestroyAccelerationStructureKHR-accelerationStructure-02442";
constexpr const char kBufferInUse[] = "VUID-vkDestroyBuffer-buffer-00922";
constexpr const char kMemoryInUse[] = "VUID-vkFreeMemory-memory-00677";

void CountSkips(const CheckContext& ctx, const InFlightSkips& skips) {
  DeviceState::LifetimeCounters& c = ctx.state.lifetime_counters;
  c.calls_judged.fetch_add(1, std::memory_order_relaxed);
  c.skipped_no_fence.fetch_add(skips.no_fence, std::memory_order_relaxed);
  c.skipped_host_may_know.fetch_add(skips.host_may_know, std::memory_order_relaxed);
}

// The structure an operation names, as the batch submitted it: alive then (created before the submission).
std::shared_ptr<const AccelerationStructureState> StructureOf(const CheckContext& ctx, VkAccelerationStructureKHR as,
                                                              uint64_t submitted) {
  if (!as) return nullptr;
  std::optional<std::shared_ptr<const AccelerationStructureState>> record = ctx.state.acceleration_structures.find(as);
  if (!record || !*record || (*record)->serial > submitted) return nullptr;
  return *record;
}

// Where an operation of a batch came from, for the message.
std::string Describe(const InFlightBatch& batch, const AsOp& op) {
  return fmt::format("{}, submitted to VkQueue 0x{:x} by {} pSubmits[{}]", DescribeOrigin(op.origin),
                     reinterpret_cast<uint64_t>(batch.queue), batch.function ? batch.function : "a submission",
                     batch.submit_index);
}

// The structures an operation names by handle, as f(structure, serial): its source and destination (serial 0: the
// handle as created before the submission), and for a trace or dispatch (family traces) the structures its bound
// descriptors name, with the serial each had when written (a set's binding, or a descriptor buffer's bytes, are read
// now: what a pending command reads cannot be rewritten before it completes).
template <typename F>
void ForEachStructure(const CheckContext& ctx, const OpBatch& batch, const AsOp& op, F&& f) {
  if (op.src) f(op.src, uint64_t{0});
  if (op.dst) f(op.dst, uint64_t{0});
  if (op.kind != OpKind::kTrace) return;
  const TracedBinding* bindings = batch.traced().begin() + op.first_geometry;
  for (uint32_t i = 0; i < op.geometry_count; ++i) {
    const TracedBinding& b = bindings[i];
    if (b.source == TracedSource::kPushed && b.pushed && b.pushed_serial) f(b.pushed, b.pushed_serial);
    if (b.source == TracedSource::kBuffer) {
      ForEachBufferDescriptor(ctx.state, b.descriptor_address, b.descriptor_count,
                              [&](BufferDescriptor what, const AccelerationStructureState* s) {
                                if (what == BufferDescriptor::kStructure) f(s->handle, s->serial);
                              });
    }
    if (b.source != TracedSource::kSet) continue;
    ctx.state.ray_bindings.ForEachIn(b.set, b.binding, [&](const DescribedStructure& d) {
      if (d.as && d.serial) f(d.as, d.serial);
    });
  }
}

template <typename Uses>
void ForEachOp(const InFlightBatch& batch, Uses&& uses) {
  for (const std::shared_ptr<const RecordedOps>& recorded : batch.recorded) {
    if (!recorded) continue;
    for (const AsOp& op : recorded->batch.ops()) uses(*recorded, op);
  }
}

[[gnu::cold, gnu::noinline]] bool Report(const CheckContext& ctx, const char* vuid, const char* function,
                                         ReportObject object, const std::string& text) {
  return ctx.reporter.Report(Severity::kError, vuid, Location(function), {object}, text);
}

constexpr const char kNotDone[] =
    "; that submission has not completed execution (its fence is unsignaled), and the device would read or write "
    "freed memory";

// The first top level a batch's traces read whose build referenced a structure of `candidates` that is still the one
// referenced (`serial_of(as)`: its live serial, 0 when none): the device traverses it (*bottom) while the batch runs
// (traced_tops.h). Null: none. A binary search per candidate and top level.
template <typename SerialOf>
const InFlightBatch::TracedTop* TracedThrough(const InFlightBatch& b, const VkAccelerationStructureKHR* candidates,
                                              std::size_t count, SerialOf&& serial_of,
                                              VkAccelerationStructureKHR* bottom) {
  for (const InFlightBatch::TracedTop& t : b.traced_tops) {
    for (std::size_t k = 0; k < count; ++k) {
      const ReferencedStructures::Referenced* r = t.references->Find(candidates[k]);
      if (!r || r->serial != serial_of(candidates[k])) continue;
      *bottom = candidates[k];
      return &t;
    }
  }
  return nullptr;
}

std::string DescribeTraced(const InFlightBatch& b, const InFlightBatch::TracedTop& t) {
  return fmt::format("{} traces the top-level VkAccelerationStructureKHR 0x{:x}, whose build it reads referenced it",
                     Describe(b, *t.op), reinterpret_cast<uint64_t>(t.top));
}

constexpr const char kBottomLevelInvalidWhy[] =
    ". Bottom-level structures must be valid when a top level referencing them is accessed (the chapter gives this "
    "rule no VUID)";

}  // namespace

bool CheckDestroyStructureInUse(const CheckContext& ctx, InFlight& in_flight, VkAccelerationStructureKHR structure) {
  if (!ctx.Enabled(kCheckLifetime) || in_flight.Empty()) return false;
  const std::shared_ptr<const AccelerationStructureState> record = StructureOf(ctx, structure, ~uint64_t{0});
  if (!record) return false;
  const auto uses = [&](const RecordedOps& recorded, const AsOp& op) {
    bool used = false;
    ForEachStructure(ctx, recorded.batch, op, [&](VkAccelerationStructureKHR as, uint64_t serial) {
      used |= as == structure && (serial == 0 || serial == record->serial);
    });
    return used;
  };
  // Family traces: a pending trace traverses it through a top level whose build referenced it.
  const bool traces = ctx.Enabled(kCheckTraces);
  const auto serial_of = [&](VkAccelerationStructureKHR) { return record->serial; };
  const auto traced_through = [&](const InFlightBatch& b) {
    VkAccelerationStructureKHR bottom = VK_NULL_HANDLE;
    return traces ? TracedThrough(b, &structure, 1, serial_of, &bottom) : nullptr;
  };
  InFlightSkips skips;
  std::vector<std::pair<const char*, std::string>> findings;  // reported once the in-flight set's lock is released
  in_flight.ForEachRunning(
      [&](const InFlightBatch& b) {
        if (b.serial < record->serial) return false;
        bool used = false;
        ForEachOp(b, [&](const RecordedOps& recorded, const AsOp& op) { used = used || uses(recorded, op); });
        return used || traced_through(b) != nullptr;
      },
      [&](const InFlightBatch& b) {
        const AsOp* first = nullptr;
        ForEachOp(b, [&](const RecordedOps& recorded, const AsOp& op) {
          if (!first && uses(recorded, op)) first = &op;
        });
        if (first) {
          findings.emplace_back(kStructureInUse,
                                fmt::format("VkAccelerationStructureKHR 0x{:x} is destroyed while {} uses it{}.",
                                            reinterpret_cast<uint64_t>(structure), Describe(b, *first), kNotDone));
        } else if (const InFlightBatch::TracedTop* t = traced_through(b)) {
          findings.emplace_back(
              kBottomLevelInvalidId,
              fmt::format("The bottom-level VkAccelerationStructureKHR 0x{:x} is destroyed while {}{}{}.",
                          reinterpret_cast<uint64_t>(structure), DescribeTraced(b, *t), kNotDone,
                          kBottomLevelInvalidWhy));
        }
      },
      &skips);
  CountSkips(ctx, skips);
  bool skip = false;
  for (const auto& [id, text] : findings) {
    skip |= Report(ctx, id, "vkDestroyAccelerationStructureKHR",
                   Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, structure), text);
  }
  return skip;
}

namespace {

// Where the object being destroyed or freed can be used: the device-address ranges of the buffers that go with it and
// the structures created on them. A touched address outside every range, or an operation naming none of those
// structures, cannot use it: no lookup is made for those (a destroy while thousands of builds are in flight walks
// their addresses with a compare each).
struct Going {
  std::vector<std::pair<VkDeviceAddress, VkDeviceSize>> ranges;  // [base, base + size)
  std::vector<VkAccelerationStructureKHR> structures;

  bool Touches(VkDeviceAddress address) const {
    for (const auto& [base, size] : ranges) {
      if (address >= base && address - base < size) return true;
    }
    return false;
  }
  bool Names(VkAccelerationStructureKHR as) const {
    return as && std::find(structures.begin(), structures.end(), as) != structures.end();
  }
  // Adds a buffer that goes: its addresses, and the structures created on it.
  void Add(const CheckContext& ctx, const BufferState& buffer) {
    if (buffer.device_address != 0) ranges.emplace_back(buffer.device_address, buffer.size);
    if (!(buffer.usage & VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR)) return;
    const VkBuffer handle = buffer.handle;
    const uint64_t id = buffer.id;
    for (const auto& [as, record] : ctx.state.acceleration_structures.snapshot(
             [&](VkAccelerationStructureKHR, const std::shared_ptr<const AccelerationStructureState>& s) {
               return s && s->buffer == handle && s->buffer_id == id;
             })) {
      structures.push_back(as);
    }
  }
  bool empty() const { return ranges.empty() && structures.empty(); }
};

// What a pending batch uses of the object being destroyed: the first operation found, and how.
struct FoundUse {
  const AsOp* op = nullptr;
  std::string how;
};

// The first use of a buffer or memory by a batch: `lost(holder)` says whether a buffer holding a touched address (or a
// structure's buffer) goes away with the object; a touched address is used only when every holder that stays...
// none does and one goes.
template <typename Goes>
FoundUse FirstUse(const CheckContext& ctx, const InFlightBatch& b, const Going& going_away, Goes&& goes) {
  FoundUse found;
  for (const std::shared_ptr<const RecordedOps>& recorded : b.recorded) {
    if (!recorded) continue;
    const std::vector<AsOp>& ops = recorded->batch.ops();
    for (const AddressTouch& touch : recorded->batch.touches()) {
      if (!going_away.Touches(touch.address)) continue;
      bool going = false, staying = false;
      ForEachBufferHolding(ctx.state, touch.address, b.serial, [&](const BufferState& holder) {
        if (!holder.memory_freed) (goes(holder) ? going : staying) = true;
      });
      if (going && !staying && touch.op < ops.size()) {
        found.op = &ops[touch.op];
        found.how = fmt::format("its {} (0x{:x})", TouchRoleName(touch.role), touch.address);
        return found;
      }
    }
    for (const AsOp& op : ops) {
      ForEachStructure(ctx, recorded->batch, op, [&](VkAccelerationStructureKHR as, uint64_t serial) {
        if (found.op || !going_away.Names(as)) return;
        const std::shared_ptr<const AccelerationStructureState> s = StructureOf(ctx, as, b.serial);
        if (!s || (serial != 0 && s->serial != serial)) return;
        const std::shared_ptr<const BufferState> buffer = BufferOfStructure(ctx.state, *s);
        if (!buffer || !buffer->bound || buffer->bound_serial > b.serial || !goes(*buffer)) return;
        found.op = &op;
        found.how = fmt::format("the storage of VkAccelerationStructureKHR 0x{:x}", reinterpret_cast<uint64_t>(as));
      });
      if (found.op) return found;
    }
  }
  return found;
}

// bottom_levels: a structure going with the object that a pending trace traverses through a top level (family
// traces) is reported too (a freed memory; a destroyed buffer whose memory stays is not judged, as at submission).
template <typename Goes>
bool CheckInUse(const CheckContext& ctx, InFlight& in_flight, const char* vuid, const char* function,
                ReportObject object, const char* what, const Going& going_away, bool bottom_levels, Goes&& goes) {
  if (going_away.empty()) return false;  // no address and no structure: nothing in flight can use it
  const bool traces = bottom_levels && ctx.Enabled(kCheckTraces) && !going_away.structures.empty();
  const auto serial_of = [&](VkAccelerationStructureKHR as) -> uint64_t {
    const std::optional<std::shared_ptr<const AccelerationStructureState>> live =
        ctx.state.acceleration_structures.find(as);
    return live && *live ? (*live)->serial : 0;
  };
  const auto traced_through = [&](const InFlightBatch& b, VkAccelerationStructureKHR* bottom) {
    return traces ? TracedThrough(b, going_away.structures.data(), going_away.structures.size(), serial_of, bottom)
                  : nullptr;
  };
  InFlightSkips skips;
  std::vector<std::pair<const char*, std::string>> findings;  // reported once the in-flight set's lock is released
  in_flight.ForEachRunning(
      [&](const InFlightBatch& b) {
        VkAccelerationStructureKHR bottom = VK_NULL_HANDLE;
        return FirstUse(ctx, b, going_away, goes).op != nullptr || traced_through(b, &bottom) != nullptr;
      },
      [&](const InFlightBatch& b) {
        const FoundUse use = FirstUse(ctx, b, going_away, goes);
        if (use.op) {
          findings.emplace_back(vuid,
                                fmt::format("{} holds {} of {}{}.", what, use.how, Describe(b, *use.op), kNotDone));
          return;
        }
        VkAccelerationStructureKHR bottom = VK_NULL_HANDLE;
        const InFlightBatch::TracedTop* t = traced_through(b, &bottom);
        if (!t) return;
        findings.emplace_back(kBottomLevelInvalidId,
                              fmt::format("{} holds the storage of the bottom-level VkAccelerationStructureKHR 0x{:x} "
                                          "while {}{}{}.",
                                          what, reinterpret_cast<uint64_t>(bottom), DescribeTraced(b, *t), kNotDone,
                                          kBottomLevelInvalidWhy));
      },
      &skips);
  CountSkips(ctx, skips);
  bool skip = false;
  for (const auto& [id, text] : findings) skip |= Report(ctx, id, function, object, text);
  return skip;
}

}  // namespace

bool CheckDestroyBufferInUse(const CheckContext& ctx, InFlight& in_flight, VkBuffer buffer) {
  if (!ctx.Enabled(kCheckLifetime) || in_flight.Empty()) return false;
  std::optional<std::shared_ptr<const BufferState>> record = ctx.state.buffers.find(buffer);
  if (!record || !*record || !(*record)->bound) return false;
  const uint64_t id = (*record)->id;
  Going going;
  going.Add(ctx, **record);
  const std::string what = fmt::format("VkBuffer 0x{:x}", reinterpret_cast<uint64_t>(buffer));
  return CheckInUse(ctx, in_flight, kBufferInUse, "vkDestroyBuffer", Obj(VK_OBJECT_TYPE_BUFFER, buffer), what.c_str(),
                    going, /*bottom_levels=*/false, [&](const BufferState& holder) { return holder.id == id; });
}

bool CheckFreeMemoryInUse(const CheckContext& ctx, InFlight& in_flight, VkDeviceMemory memory) {
  if (!ctx.Enabled(kCheckLifetime) || in_flight.Empty()) return false;
  const std::string what = fmt::format("VkDeviceMemory 0x{:x}", reinterpret_cast<uint64_t>(memory));
  // A buffer on it whose destroy was kept back because pending work uses it: that work uses this memory.
  if (const VkBuffer kept = in_flight.DeferredBufferOn(memory)) {
    return Report(ctx, kMemoryInUse, "vkFreeMemory", Obj(VK_OBJECT_TYPE_DEVICE_MEMORY, memory),
                  fmt::format("{} is bound to VkBuffer 0x{:x}, destroyed while a pending submission used it (the layer "
                              "keeps it until that submission completes){}.",
                              what, reinterpret_cast<uint64_t>(kept), kNotDone));
  }
  Going going;
  for (const auto& [handle, b] : ctx.state.buffers.snapshot([&](VkBuffer, const std::shared_ptr<const BufferState>& s) {
         return s && s->bound && s->memory == memory;
       })) {
    going.Add(ctx, *b);
  }
  return CheckInUse(ctx, in_flight, kMemoryInUse, "vkFreeMemory", Obj(VK_OBJECT_TYPE_DEVICE_MEMORY, memory),
                    what.c_str(), going, /*bottom_levels=*/true,
                    [&](const BufferState& holder) { return holder.memory == memory; });
}

void ReportLifetimeSummary(const DeviceState& state, Reporter& reporter, VkDevice device) {
  const DeviceState::LifetimeCounters& c = state.lifetime_counters;
  const uint64_t judged = c.calls_judged.load(std::memory_order_relaxed);
  const uint64_t recorded = c.recorded_judged.load(std::memory_order_relaxed);
  const NamedCount reasons[] = {{"no_fence", c.skipped_no_fence.load(std::memory_order_relaxed)},
                                {"host_may_know", c.skipped_host_may_know.load(std::memory_order_relaxed)},
                                {"recorded_forgotten", c.skipped_recorded_forgotten.load(std::memory_order_relaxed)}};
  if (judged == 0 && recorded == 0 && reasons[2].count == 0) return;
  const std::string text = fmt::format(
      "Objects in use by the device (lifetime): {} destroys and frees were judged against the work in flight, {} of "
      "them made by the layer once that work completed (the app's callback or protect mode skipped them); {} recorded "
      "objects were found destroyed before their command buffer's submission. Not judged: no_fence={} (pending "
      "batches with no fence to ask), host_may_know={} (pending batches the host may have known complete before their "
      "fence: it read an event or query results, or another queue waited for their binary semaphore), "
      "recorded_forgotten={} (recorded objects destroyed longer ago than the layer remembers destroys).",
      judged, c.kept_back.load(std::memory_order_relaxed), recorded, reasons[0].count, reasons[1].count,
      reasons[2].count);
  const NamedCounts counts{"lifetime_skipped", reasons, 3};
  const Location where("vkDestroyDevice");
  if (reasons[0].count + reasons[1].count + reasons[2].count != 0) {
    reporter.ReportUnchecked(kLifetimeSummaryId, where, {Obj(VK_OBJECT_TYPE_DEVICE, device)}, text, counts);
  } else {
    reporter.Report(Severity::kInfo, kLifetimeSummaryId, where, {Obj(VK_OBJECT_TYPE_DEVICE, device)}, text, counts);
  }
}

}  // namespace asval
