#include "traced_structures.h"

#include <fmt/format.h>

#include <string>

#include "buffer_descriptors.h"
#include "build_report.h"
#include "structure_memory.h"

namespace asval {

namespace {

constexpr const char kTraceRayBuilt[] = "VUID-RuntimeSpirv-OpTraceRayKHR-06359";
constexpr const char kRayQueryBuilt[] = "VUID-RuntimeSpirv-OpRayQueryInitializeKHR-06352";

struct TracedJudge {
  const DeviceState& state;
  const HistoryStore& store;
  const AsOp& op;
  const HistoryCheckSite& site;
  HistoryFindings& out;

  void Skip(TracedSkip why) const {
    state.trace_counters.skipped[static_cast<std::size_t>(why)].fetch_add(1, std::memory_order_relaxed);
  }

  // Where the structure came from, for the message.
  static std::string Through(const TracedBinding& b) {
    if (b.source == TracedSource::kPushed) {
      return fmt::format("pushed at set {} binding {}", b.set_index, b.binding);
    }
    if (b.source == TracedSource::kBuffer) {
      return fmt::format("through the descriptor buffer bytes at 0x{:x}, set {} binding {}", b.descriptor_address,
                         b.set_index, b.binding);
    }
    return fmt::format("through VkDescriptorSet {} bound at set {}, binding {}", Hex(b.set), b.set_index, b.binding);
  }

  // The descriptors of a binding read from a descriptor buffer (buffer_descriptors.h).
  void JudgeBuffer(const TracedBinding& b) const {
    ForEachBufferDescriptor(state, b.descriptor_address, b.descriptor_count,
                            [&](BufferDescriptor what, const AccelerationStructureState* s) {
                              switch (what) {
                                case BufferDescriptor::kUnreadable:
                                  return Skip(TracedSkip::kUnreadable);
                                case BufferDescriptor::kUnknownStructure:
                                  return Skip(TracedSkip::kUnknownStructure);
                                case BufferDescriptor::kNull:
                                  return;
                                case BufferDescriptor::kStructure:
                                  return Judge(b, DescribedStructure{s->handle, s->serial});
                              }
                            });
  }

  void Judge(const TracedBinding& b, const DescribedStructure& d) const {
    if (d.as == VK_NULL_HANDLE) return;  // a null descriptor (nullDescriptor): nothing is read
    if (d.serial == 0) return Skip(TracedSkip::kUnknownStructure);
    const std::optional<std::shared_ptr<const AccelerationStructureState>> now =
        state.acceleration_structures.find(d.as);
    if (!now || !*now || (*now)->serial != d.serial) return Skip(TracedSkip::kDestroyed);
    const AsHistory* h = store.Find(d.as);  // a live structure without a record was never built
    if (h && h->kind == HistoryKind::kUnknown) {
      store.rules_skipped_unknown_history.fetch_add(1, std::memory_order_relaxed);
      return Skip(TracedSkip::kUnknownHistory);
    }
    state.trace_counters.judged.fetch_add(1, std::memory_order_relaxed);
    const bool built = h && h->kind == HistoryKind::kBuilt && h->build;
    if (built && h->build->type != VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR) return JudgeReferenced(b, d.as, *h);
    Report(b, d.as, built ? h : nullptr);
  }

  // The bottom-level structures the top level's last build referenced are still the same live structures, their
  // storage still bound, and not rebuilt since with another geometry layout.
  void JudgeReferenced(const TracedBinding& b, VkAccelerationStructureKHR top, const AsHistory& h) const {
    const std::shared_ptr<const ReferencedStructures> refs = h.activity ? h.activity->references() : nullptr;
    if (!refs) {
      // Built earlier in this same submission: the host cannot have destroyed anything between that build and this
      // trace, and the build's own references are judged when it completes (pInfos-06707). Otherwise not known yet.
      if (h.activity && site.submission != 0 && h.activity->submission() == site.submission) return;
      return Skip(TracedSkip::kReferencesUnknown);
    }
    // Nothing that could change the answer happened since the last walk found nothing: no walk. Each stamp only
    // grows, so their sum changes whenever one of them does.
    const uint64_t stamps_now = state.acceleration_structures.stamp().count +
                                state.structure_storage_changes.Read().count + store.bottom_layout_changes() + 1;
    if (refs->verified_structures.load(std::memory_order_relaxed) == stamps_now) return;
    bool found = false;
    for (const ReferencedStructures::Referenced& r : refs->structures) {
      const std::optional<std::shared_ptr<const AccelerationStructureState>> now =
          state.acceleration_structures.find(r.as);
      if (!now || !*now || (*now)->serial != r.serial) {
        ReportReferenced(b, top, h, r.as, "was destroyed since");
        found = true;
        continue;
      }
      // A structure whose buffer was destroyed while its memory stays is not judged (engines relocate so); nor one
      // on a buffer the layer does not know or cannot follow (sparse): counted.
      const StructureStorage storage = StorageOfStructure(state, **now);
      if (storage == StructureStorage::kMemoryFreed) {
        ReportReferenced(b, top, h, r.as, "is still alive, but the memory its buffer was bound to was freed since");
        found = true;
        continue;
      }
      if (storage != StructureStorage::kBound) Skip(TracedSkip::kBottomLevelUnknown);
      const AsHistory* bottom = r.build ? store.Find(r.as) : nullptr;
      // Its layout cannot be compared: no build known when the top level's completed, or its history unknown now.
      if (!bottom || bottom->kind != HistoryKind::kBuilt || !bottom->build) {
        Skip(TracedSkip::kBottomLevelUnknown);
        continue;
      }
      // A later write of it (generation: an undone submission restores an older one, never judged).
      if (bottom->build != r.build && bottom->generation > r.generation &&
          !SameGeometryLayout(*r.build, *bottom->build)) {
        ReportRebuilt(b, top, h, r, *bottom->build);
        found = true;
      }
    }
    if (!found) refs->verified_structures.store(stamps_now, std::memory_order_relaxed);
  }

  [[gnu::cold, gnu::noinline]] void ReportReferenced(const TracedBinding& b, VkAccelerationStructureKHR top,
                                                     const AsHistory& h, VkAccelerationStructureKHR bottom,
                                                     const char* what) const {
    out.Add(Severity::kError, kBottomLevelInvalidId, site.loc,
            {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, site.submitted), Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, top),
             Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, bottom)},
            fmt::format("{}: the bound pipeline's shaders read the top-level VkAccelerationStructureKHR {} ({}), whose "
                        "last build ({}) referenced the bottom-level VkAccelerationStructureKHR {}, which {}. "
                        "Bottom-level structures must be valid when the top level is accessed: rebuild the top level "
                        "without it first.",
                        DescribeOrigin(op.origin), Hex(top), Through(b), DescribeOrigin(h.build->origin), Hex(bottom),
                        what));
  }

  [[gnu::cold, gnu::noinline]] void ReportRebuilt(const TracedBinding& b, VkAccelerationStructureKHR top,
                                                  const AsHistory& h, const ReferencedStructures::Referenced& r,
                                                  const BuildSnapshot& now) const {
    out.Add(Severity::kWarning, kBottomLevelChangedId, site.loc,
            {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, site.submitted), Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, top),
             Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, r.as)},
            fmt::format("{}: the bound pipeline's shaders read the top-level VkAccelerationStructureKHR {} ({}), whose "
                        "last build ({}) referenced the bottom-level VkAccelerationStructureKHR {} as {} built it "
                        "({} geometries); {} has rebuilt it since with another geometry layout ({} geometries). The "
                        "top level's instances still describe the old structure (bounds, geometry indices into the "
                        "shader binding table): what traversal finds is not defined. Rebuild or update the top level "
                        "after rebuilding a bottom level it references.",
                        DescribeOrigin(op.origin), Hex(top), Through(b), DescribeOrigin(h.build->origin), Hex(r.as),
                        DescribeOrigin(r.build->origin), r.build->geometries.size(), DescribeOrigin(now.origin),
                        now.geometries.size()));
  }

  // built_bottom: the history of a structure whose last build made a bottom-level one; null: never built.
  [[gnu::cold, gnu::noinline]] void Report(const TracedBinding& b, VkAccelerationStructureKHR as,
                                           const AsHistory* built_bottom) const {
    const bool trace = b.by == TracedBy::kTraceRay;
    const char* instruction = trace ? "OpTraceRayKHR" : "OpRayQueryInitializeKHR";
    const std::string what = built_bottom
                                 ? fmt::format("the build that last executed on it ({}) made a bottom-level structure",
                                               DescribeOrigin(built_bottom->build->origin))
                                 : std::string("no build has executed on it before this command, in submission order");
    out.Add(Severity::kError, trace ? kTraceRayBuilt : kRayQueryBuilt, site.loc,
            {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, site.submitted), Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, as),
             Obj(VK_OBJECT_TYPE_DESCRIPTOR_SET, b.source == TracedSource::kSet ? b.set : VK_NULL_HANDLE)},
            fmt::format("{}: the bound pipeline's shaders read VkAccelerationStructureKHR {} ({}) and use {}, which "
                        "needs a structure built as a top-level acceleration structure; {}. Build it (or rewrite "
                        "the descriptor) before this command executes.",
                        DescribeOrigin(op.origin), Hex(as), Through(b), instruction, what));
  }
};

}  // namespace

const char* TracedSkipName(TracedSkip skip) {
  switch (skip) {
    case TracedSkip::kNotBound:
      return "not_bound";
    case TracedSkip::kNotWritten:
      return "not_written";
    case TracedSkip::kUnreadable:
      return "unreadable_descriptors";
    case TracedSkip::kUnknownStructure:
      return "unknown_structure";
    case TracedSkip::kDestroyed:
      return "destroyed";
    case TracedSkip::kUnknownHistory:
      return "unknown_history";
    case TracedSkip::kReferencesUnknown:
      return "references_unknown";
    case TracedSkip::kBottomLevelUnknown:
      return "bottom_level_unknown";
    case TracedSkip::kCount:
      break;
  }
  return "?";
}

void CheckTracedStructures(const DeviceState& state, const HistoryStore& store, const OpBatch& batch, const AsOp& op,
                           const HistoryCheckSite& site, HistoryFindings& out) {
  const TracedJudge judge{state, store, op, site, out};
  const TracedBinding* bindings = batch.traced().begin() + op.first_geometry;
  for (uint32_t i = 0; i < op.geometry_count; ++i) {
    const TracedBinding& b = bindings[i];
    switch (b.source) {
      case TracedSource::kNotBound:
        judge.Skip(TracedSkip::kNotBound);
        break;
      case TracedSource::kUnknown:
        judge.Skip(TracedSkip::kUnreadable);
        break;
      case TracedSource::kPushed:
        judge.Judge(b, DescribedStructure{b.pushed, b.pushed_serial});
        break;
      case TracedSource::kBuffer:
        judge.JudgeBuffer(b);
        break;
      case TracedSource::kSet: {
        const SetLookup found =
            state.ray_bindings.ForEachIn(b.set, b.binding, [&](const DescribedStructure& d) { judge.Judge(b, d); });
        if (found == SetLookup::kNotWritten) judge.Skip(TracedSkip::kNotWritten);
        if (found == SetLookup::kUnknown) judge.Skip(TracedSkip::kUnreadable);
        break;
      }
    }
  }
}

void ReportTracesSummary(const DeviceState& state, Reporter& reporter, VkDevice device) {
  const DeviceState::TraceCounters& c = state.trace_counters;
  constexpr std::size_t kReasons = static_cast<std::size_t>(TracedSkip::kCount);
  static_assert(kReasons == std::tuple_size_v<decltype(c.skipped)>, "one counter per reason");
  NamedCount reasons[kReasons];
  uint64_t skipped = 0;
  for (std::size_t i = 0; i < kReasons; ++i) {
    reasons[i] = NamedCount{TracedSkipName(static_cast<TracedSkip>(i)), c.skipped[i].load(std::memory_order_relaxed)};
    skipped += reasons[i].count;
  }
  const uint64_t judged = c.judged.load(std::memory_order_relaxed);
  if (judged + skipped == 0) return;
  std::string text = fmt::format(
      "Structures traced (traces): {} structures read by trace and ray-query commands were judged at submission; not "
      "judged:",
      judged);
  for (const NamedCount& r : reasons) text += fmt::format(" {}={}", r.name, r.count);
  text +=
      ". Structures a shader reaches from a device address (OpConvertUToAccelerationStructureKHR) are not followed.";
  const NamedCounts counts{"traces_skipped", reasons, kReasons};
  const Location where("vkDestroyDevice");
  if (skipped != 0) {
    reporter.ReportUnchecked(kTracesSummaryId, where, {Obj(VK_OBJECT_TYPE_DEVICE, device)}, text, counts);
  } else {
    reporter.Report(Severity::kInfo, kTracesSummaryId, where, {Obj(VK_OBJECT_TYPE_DEVICE, device)}, text, counts);
  }
}

}  // namespace asval
