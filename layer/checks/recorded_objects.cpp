#include "recorded_objects.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <string>

#include "buffer_lookup.h"
#include "build_report.h"

namespace asval {

namespace {

constexpr const char kSubmitInvalid[] = "VUID-vkQueueSubmit-pCommandBuffers-00070";
constexpr const char kSubmit2Invalid[] = "VUID-vkQueueSubmit2-commandBuffer-03874";

struct RecordedJudge {
  const DeviceState& state;
  const OpBatch& batch;
  const AsOp& op;
  const HistoryCheckSite& site;
  HistoryFindings& out;

  const char* Vuid() const {
    const char* f = site.loc.Function();
    return f && std::strncmp(f, "vkQueueSubmit2", 14) == 0 ? kSubmit2Invalid : kSubmitInvalid;
  }

  // One finding of this rule per submitted command buffer and object: a command buffer of many builds over one
  // destroyed scratch buffer is reported once (another rule's finding about the same object is not this one).
  bool Reported(uint64_t object) const {
    const char* vuid = Vuid();
    for (const HistoryFinding& f : out.list()) {
      if (f.vuid == vuid && f.objects[0].handle == reinterpret_cast<uint64_t>(site.submitted) &&
          f.objects[1].handle == object) {
        return true;
      }
    }
    return false;
  }

  ObjectLifetimes::Between Between() const {
    return {op.origin.recorded_at, site.submitted_at != 0 ? site.submitted_at : ~uint64_t{0}};
  }

  void Forgotten() const { state.lifetime_counters.skipped_recorded_forgotten.fetch_add(1, std::memory_order_relaxed); }

  void Structure(VkAccelerationStructureKHR as, const char* role) const {
    if (!as) return;
    const std::optional<std::shared_ptr<const AccelerationStructureState>> now = state.acceleration_structures.find(as);
    if (now && *now && (*now)->serial <= op.origin.recorded_at) return;  // the structure recorded still lives
    ObjectLifetimes::Structure gone{};
    switch (state.lifetimes.StructureDestroyedSince(as, Between(), &gone)) {
      case ObjectLifetimes::Answer::kNo:
        return;  // the handle named no structure when recorded: another rule's
      case ObjectLifetimes::Answer::kUnknown:
        return Forgotten();
      case ObjectLifetimes::Answer::kYes:
        break;
    }
    state.lifetime_counters.recorded_judged.fetch_add(1, std::memory_order_relaxed);
    if (Reported(reinterpret_cast<uint64_t>(as))) return;
    ReportStructure(as, role, now && *now);
  }

  void Address(const AddressTouch& touch) const {
    if (touch.address == 0) return;
    // Still in a live buffer bound when the command was recorded (an alias over the same memory stays): valid.
    bool held = false;
    ForEachBufferHolding(state, touch.address, op.origin.recorded_at, [&](const BufferState&) { held = true; });
    if (held) return;
    ObjectLifetimes::Buffer gone{};
    switch (state.lifetimes.BufferDestroyedSince(touch.address, Between(), &gone)) {
      case ObjectLifetimes::Answer::kNo:
        return;  // in no buffer when recorded: the address rules' business
      case ObjectLifetimes::Answer::kUnknown:
        return Forgotten();
      case ObjectLifetimes::Answer::kYes:
        break;
    }
    state.lifetime_counters.recorded_judged.fetch_add(1, std::memory_order_relaxed);
    if (Reported(reinterpret_cast<uint64_t>(gone.handle))) return;
    ReportBuffer(touch, gone);
  }

  [[gnu::cold, gnu::noinline]] void ReportStructure(VkAccelerationStructureKHR as, const char* role,
                                                    bool handle_reused) const {
    out.Add(Severity::kError, Vuid(), site.loc,
            {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, site.submitted), Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, as),
             ReportObject{}},
            fmt::format("VkCommandBuffer {} is invalid: {} recorded VkAccelerationStructureKHR {} as its {}, and that "
                        "structure was destroyed since{}. A command buffer whose recorded objects are destroyed must "
                        "be recorded again before it is submitted.",
                        Hex(site.submitted), DescribeOrigin(op.origin), Hex(as), role,
                        handle_reused ? " (the handle now names another structure, created after the recording)" : ""));
  }

  [[gnu::cold, gnu::noinline]] void ReportBuffer(const AddressTouch& touch, const ObjectLifetimes::Buffer& gone) const {
    out.Add(
        Severity::kError, Vuid(), site.loc,
        {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, site.submitted), Obj(VK_OBJECT_TYPE_BUFFER, gone.handle), ReportObject{}},
        fmt::format("VkCommandBuffer {} is invalid: {} recorded the address 0x{:x} as its {}, in VkBuffer {} "
                    "(0x{:x}, {} bytes), and that buffer was destroyed since, with no other buffer bound then "
                    "holding the address. A command buffer whose recorded objects are destroyed must be recorded "
                    "again before it is submitted.",
                    Hex(site.submitted), DescribeOrigin(op.origin), touch.address, TouchRoleName(touch.role),
                    Hex(gone.handle), gone.address, gone.size));
  }
};

// The structure roles an operation names, for the message.
const char* SourceRole(const AsOp& op) {
  return op.kind == OpKind::kBuild ? "update source (srcAccelerationStructure)" : "source (src)";
}
const char* DestinationRole(const AsOp& op) {
  switch (op.kind) {
    case OpKind::kBuild:
      return "destination (dstAccelerationStructure)";
    case OpKind::kWriteProperties:
      return "queried structure (pAccelerationStructures)";
    default:
      return "destination (dst)";
  }
}

}  // namespace

void CheckRecordedObjects(const DeviceState& state, const OpBatch& batch, const AsOp& op, const HistoryCheckSite& site,
                          HistoryFindings& out) {
  const uint64_t recorded_at = op.origin.recorded_at;
  if (recorded_at == 0 || op.kind == OpKind::kTrace) return;  // host calls; traces are family traces'
  const RecordedJudge judge{state, batch, op, site, out};
  if (state.lifetimes.last_structure_destroyed() > recorded_at) {
    judge.Structure(op.src, SourceRole(op));
    judge.Structure(op.dst, DestinationRole(op));
  }
  if (state.lifetimes.last_buffer_destroyed() > recorded_at) {
    // The batch's touches are in operation order (OpBatch appends them so).
    const uint32_t index = static_cast<uint32_t>(&op - batch.ops().data());
    const AddressTouch* first = std::lower_bound(batch.touches().begin(), batch.touches().end(), index,
                                                 [](const AddressTouch& t, uint32_t i) { return t.op < i; });
    for (const AddressTouch* t = first; t != batch.touches().end() && t->op == index; ++t) judge.Address(*t);
  }
}

}  // namespace asval
