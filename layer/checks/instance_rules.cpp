#include "instance_rules.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "build_report.h"
#include "capture_notices.h"
#include "structure_memory.h"

namespace asval {

namespace {

constexpr std::size_t kNamed = 4;               // references named in a message; the rest are counted
constexpr uint32_t kMaxStructureFindings = 16;  // per build and rule: enough to show the pattern
constexpr VkDeviceSize kInstanceBytes = sizeof(VkAccelerationStructureInstanceKHR);
constexpr std::size_t kReferenceOffset = offsetof(VkAccelerationStructureInstanceKHR, accelerationStructureReference);

// A live structure the build's instances reference, and the first instance that does (for messages).
struct Referenced {
  std::ptrdiff_t structure;  // index in the live snapshot
  uint32_t geometry;
  uint32_t instance;
};

[[gnu::cold]] void Report(const CheckContext& ctx, const InstanceReferenceCheck& c, const char* rule,
                          VkAccelerationStructureKHR referenced, const std::string& message) {
  const char* command = OpCommandName(c.build.command);
  const std::string vuid = fmt::format("VUID-{}-{}", command, rule);
  if (referenced == VK_NULL_HANDLE) {
    ctx.reporter.Report(Severity::kError, vuid, Location(command),
                        {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, c.build.command_buffer),
                         Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, c.dst)},
                        message);
    return;
  }
  ctx.reporter.Report(Severity::kError, vuid, Location(command),
                      {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, c.build.command_buffer),
                       Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, c.dst),
                       Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, referenced)},
                      message);
}

// The rule about what an instance references: the indirect command's newest text of it is pInfos-12281 (its
// pInfos-06707 is that rule's older name), the direct command's is pInfos-06707.
const char* ReferenceRule(const InstanceReferenceCheck& c) {
  return c.build.command == OpCommand::kCmdBuildIndirect ? "pInfos-12281" : "pInfos-06707";
}

[[gnu::cold]] void ReportStale(const CheckContext& ctx, const InstanceReferenceCheck& c, uint32_t geometry,
                               uint64_t bad, const std::string& named) {
  Report(ctx, c, ReferenceRule(c), VK_NULL_HANDLE,
         fmt::format("{}: builds top-level {}; on execution, geometry {}: {} instance(s) reference no acceleration "
                     "structure that was alive when the build was submitted (not 0 and not an address "
                     "vkGetAccelerationStructureDeviceAddressKHR returned for a live structure): {}.",
                     DescribeOrigin(c.build), Hex(c.dst), geometry, bad, named));
}

[[gnu::cold]] void ReportTopLevel(const CheckContext& ctx, const InstanceReferenceCheck& c, uint32_t geometry,
                                  uint64_t count, const std::string& named) {
  Report(ctx, c, ReferenceRule(c), VK_NULL_HANDLE,
         fmt::format("{}: builds top-level {}; on execution, geometry {}: {} instance(s) reference a top-level "
                     "acceleration structure, but an instance must reference a bottom-level one (the top level takes "
                     "a reference to the bottom-level structures its instances reference; the indirect command's "
                     "newest text of this rule, pInfos-12281, says \"a valid bottom level acceleration "
                     "structure\"): {}.",
                     DescribeOrigin(c.build), Hex(c.dst), geometry, count, named));
}

// "geometry 0, instance 3 references VkAccelerationStructureKHR 0x... (address 0x...)".
std::string Referencing(const Referenced& r, const AccelerationStructureState& s) {
  return fmt::format("geometry {}, instance {} references VkAccelerationStructureKHR {} (address 0x{:x})", r.geometry,
                     r.instance, Hex(s.handle), s.device_address);
}

[[gnu::cold]] void ReportStorageLost(const CheckContext& ctx, const InstanceReferenceCheck& c, const Referenced& r,
                                     const AccelerationStructureState& s, const char* why) {
  Report(ctx, c, "pInfos-03709", s.handle,
         fmt::format("{}: builds top-level {}; on execution, {}, whose buffer (VkBuffer {}) {}.",
                     DescribeOrigin(c.build), Hex(c.dst), Referencing(r, s), Hex(s.buffer), why));
}

// pInfos-03709: the buffer the referenced structure was created on was bound to memory when the build was
// submitted (the snapshot of live structures says).
uint32_t CheckStorage(const CheckContext& ctx, const InstanceReferenceCheck& c, const Referenced& r,
                      const AccelerationStructureState& s, StructureStorage storage) {
  switch (storage) {
    case StructureStorage::kBound:
      return 0;
    case StructureStorage::kUnknown:
      CountUnknownState(ctx);
      return 0;
    case StructureStorage::kBufferDestroyed:
      ReportStorageLost(ctx, c, r, s, "was destroyed");
      return 1;
    case StructureStorage::kMemoryFreed:
      ReportStorageLost(ctx, c, r, s, "has had its memory freed");
      return 1;
    case StructureStorage::kUnbound:
      ReportStorageLost(ctx, c, r, s, "is bound to no memory");
      return 1;
  }
  return 0;
}

// None-03407 and dstAccelerationStructure-03706: the referenced structure against the other destinations of the
// call the build was recorded in. `span`: the structure's memory (null: unknown).
uint32_t CheckAgainstDestinations(const CheckContext& ctx, const InstanceReferenceCheck& c, const CaptureLog& log,
                                  const CapturedInfo& info, const Referenced& r, const AccelerationStructureState& s,
                                  const std::optional<MemorySpan>& span) {
  uint32_t findings = 0;
  for (uint32_t d = 0; d < info.destination_count; ++d) {
    const CommandDestination& other = log.destinations[info.first_destination + d];
    if (other.element == info.element) continue;
    if (other.address != 0 && other.address == s.device_address) {
      Report(ctx, c, "None-03407", s.handle,
             fmt::format("{}: builds top-level {}; on execution, {}, which is pInfos[{}].dstAccelerationStructure of "
                         "this same command.",
                         DescribeOrigin(c.build), Hex(c.dst), Referencing(r, s), other.element));
      ++findings;
    }
    // An indirect command's: known when the device's counts were the recorded maxima (ExecutedAccess).
    const MemorySpan accessed = ExecutedAccess(log, other);
    if (!span || accessed.memory == VK_NULL_HANDLE) {
      CountUnknownState(ctx);
      continue;
    }
    if (!Overlaps(*span, accessed)) continue;
    const VkDeviceSize from = std::max(span->begin, accessed.begin);
    const VkDeviceSize to = std::min(span->end, accessed.end);
    Report(ctx, c, "dstAccelerationStructure-03706", s.handle,
           fmt::format("{}: builds top-level {}; on execution, {}, whose memory overlaps the bytes this command writes "
                       "for pInfos[{}].dstAccelerationStructure (VkAccelerationStructureKHR {}): {} bytes at "
                       "[0x{:x}, 0x{:x}) of VkDeviceMemory {}.",
                       DescribeOrigin(c.build), Hex(c.dst), Referencing(r, s), other.element, Hex(other.handle),
                       to - from, from, to, Hex(accessed.memory)));
    ++findings;
  }
  return findings;
}

// The rules about one structure the build's instances reference (each family as the settings enable it).
// Returns the findings made (for the cap).
uint32_t CheckReferenced(const CheckContext& ctx, const InstanceReferenceCheck& c, const CaptureLog& log,
                         const CapturedInfo& info, const Referenced& r, std::size_t k) {
  const LiveStructureAddresses& live = *c.live;
  const std::shared_ptr<const AccelerationStructureState>& structure = live.structures[k];
  uint32_t findings = 0;
  if (ctx.Enabled(kCheckHandles)) findings += CheckStorage(ctx, c, r, *structure, live.storage[k]);
  if (!ctx.Enabled(kCheckAliasing) || info.destination_count == 0) return findings;
  // The structure's memory now (it cannot move while the build is pending); whole: which of its bytes the build
  // reads is the driver's business. Unknown when it was destroyed since, or its storage is not bound.
  std::optional<MemorySpan> span;
  if (live.storage[k] == StructureStorage::kBound) {
    const std::optional<StructureMemory> now = MemoryOfStructure(ctx.state, structure->handle);
    // Still the structure the snapshot saw (its handle value may name a newer one).
    if (now && now->structure->device_address == structure->device_address &&
        now->structure->buffer_id == structure->buffer_id) {
      span = now->Span();
    }
  }
  return findings + CheckAgainstDestinations(ctx, c, log, info, r, *structure, span);
}

// pInfos-03717: each pointer of an array of instance pointers is 16-byte aligned. The records of those that are
// not (and of null ones, which the layer does not follow either) were not gathered: counted as unknown once.
void CheckInstancePointers(const CheckContext& ctx, const InstanceReferenceCheck& c, const CaptureLog& log,
                           uint32_t geometry, const CapturedGeometry& g) {
  const uint8_t* pointers = log.Bytes(g.pointers);
  const bool alignment = ctx.Enabled(kCheckAlignment);
  uint64_t misaligned = 0, not_followed = 0;
  std::string named;
  for (uint32_t k = 0; k < g.range.primitiveCount; ++k) {
    const VkDeviceAddress pointer = InstancePointer(pointers, k);
    if (FollowedInstancePointer(pointer)) continue;
    ++not_followed;
    if (pointer == 0 || !alignment) continue;
    if (misaligned++ < kNamed) named += fmt::format("{}instance {} at 0x{:x}", misaligned > 1 ? ", " : "", k, pointer);
  }
  if (not_followed != 0 && g.data.present) CountUnknownState(ctx);
  if (misaligned == 0) return;
  if (misaligned > kNamed) named += fmt::format(" (and {} more)", misaligned - kNamed);
  Report(ctx, c, "pInfos-03717", VK_NULL_HANDLE,
         fmt::format("{}: builds top-level {}; on execution, geometry {} (arrayOfPointers): {} pointer(s) are not "
                     "aligned to 16 bytes: {}.",
                     DescribeOrigin(c.build), Hex(c.dst), geometry, misaligned, named));
}

bool BottomLevel(const AccelerationStructureState& s) {
  return s.type == VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
}

// A reduced geometry's references judged by their summaries (ReducedGeometry::Distinct): true when each names a
// live structure, `first` (when asked) then holding, per structure, the first instance referencing it (the first
// 64-record group that holds a reference holds its first record). False when one does not: the caller walks the
// records.
bool JudgeDistinctReferences(const ReducedGeometry& reduced, const LiveStructureAddresses& live, uint32_t geometry,
                             std::vector<Referenced>* first) {
  for (uint32_t group = 0; group < (reduced.count + 63) / 64; ++group) {
    const uint32_t distinct = std::min<uint32_t>(reduced.Distinct(group), 64);
    for (uint32_t e = 0; e < distinct; ++e) {
      uint64_t reference = 0;
      uint32_t instance = 0;
      reduced.DistinctReference(group, e, &reference, &instance);
      const std::ptrdiff_t structure = live.Find(reference);
      if (structure < 0 || !BottomLevel(*live.structures[static_cast<std::size_t>(structure)])) return false;
      if (first && (*first)[static_cast<std::size_t>(structure)].structure < 0) {
        (*first)[static_cast<std::size_t>(structure)] = Referenced{structure, geometry, instance};
      }
    }
  }
  return true;
}

}  // namespace

bool CheckInstanceReferences(const CheckContext& ctx, const InstanceReferenceCheck& c,
                             ReferencedStructures* referenced) {
  const CaptureLog* log = c.log.get();
  const CapturedInfo* readable = log ? log->Readable(c.info) : nullptr;
  if (!readable || !c.live) {
    CountUnknownState(ctx);
    return false;
  }
  bool complete = true;  // every reference named a known structure (what `referenced` needs)
  const CapturedInfo& info = *readable;
  const LiveStructureAddresses& live = *c.live;
  // The rules about each referenced structure (03709, the same command's destinations, degenerate instances) run
  // only where one can have something to say: a frame whose structures are all bound, built in commands of their
  // own, walks the instances once, for 06707.
  const bool per_structure = !live.all_bound || info.destination_count != 0 || !c.activities.empty();
  // Per live structure: the first instance that references it (structure -1: none). The thread's own array, kept
  // from one build to the next: a top level rebuilt every frame allocates nothing here (the capture's completions
  // run one at a time per thread; nothing below calls back into this function).
  thread_local std::vector<Referenced> first;
  first.clear();
  if (per_structure || referenced) first.assign(live.structures.size(), Referenced{-1, 0, 0});
  const bool collect = per_structure || referenced;
  for (uint32_t j = 0; j < info.geometry_count; ++j) {
    CapturedGeometry g;  // an indirect info's with its range as the device read it
    if (!ExecutedGeometry(*log, info, j, &g)) {
      CountUnknownState(ctx);
      complete = false;
      continue;
    }
    if (g.type != VK_GEOMETRY_TYPE_INSTANCES_KHR || g.range.primitiveCount == 0) continue;
    if (g.array_of_pointers) {
      if (!g.pointers.present) continue;
      CheckInstancePointers(ctx, c, *log, j, g);
      // The records, gathered by the layer's dispatch, are then judged as a plain array's (a record not followed
      // is zeros: inactive here, counted above); not gathered (capture.md says where): unknown.
      if (!g.data.present) CountUnknownState(ctx);
    }
    if (!g.data.present) {
      complete = false;
      continue;
    }
    // Reduced on the device: each 64 records' distinct references, with the first record of each, are judged
    // instead of every record; only when one names no live structure are the records walked below (for the count
    // and the instances the message names).
    if (g.reduced && JudgeDistinctReferences(log->Reduced(g), live, j, collect ? &first : nullptr)) continue;
    // The records as copied, or the references alone as the layer's dispatch wrote them (CapturedGeometry::reduced).
    const uint8_t* references = log->Bytes(g.data) + (g.reduced ? 0 : kReferenceOffset);
    const VkDeviceSize stride = g.reduced ? sizeof(uint64_t) : kInstanceBytes;
    uint64_t bad = 0;
    uint64_t top_level = 0;
    bool unknown = false;
    std::string named;
    std::string named_top_level;
    // Instances come in runs of the same structure, or cycle through a few: the last reference, and a small table
    // of those looked up (by a multiplicative hash: structure addresses share their low bits), spare most lookups.
    constexpr uint32_t kRememberedBits = 6;
    uint64_t remembered[1u << kRememberedBits] = {};
    std::ptrdiff_t remembered_structure[1u << kRememberedBits];
    uint64_t last = 0;
    std::ptrdiff_t structure = -1;
    for (uint32_t k = 0; k < g.range.primitiveCount; ++k) {
      uint64_t reference = 0;
      std::memcpy(&reference, references + k * stride, sizeof(reference));
      if (reference == 0) continue;  // an inactive instance
      if (reference != last) {
        const std::size_t memo = (reference * 0x9e3779b97f4a7c15ull) >> (64 - kRememberedBits);
        if (remembered[memo] != reference) {
          remembered[memo] = reference;
          remembered_structure[memo] = live.Find(reference);
        }
        structure = remembered_structure[memo];
        last = reference;
      }
      if (structure >= 0) {
        const AccelerationStructureState& s = *live.structures[static_cast<std::size_t>(structure)];
        if (collect && first[static_cast<std::size_t>(structure)].structure < 0) {
          first[static_cast<std::size_t>(structure)] = Referenced{structure, j, k};
        }
        if (BottomLevel(s)) continue;
        // A generic structure is bottom- or top-level as its last build made it: not judged.
        if (s.type != VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR) {
          unknown = true;
          continue;
        }
        if (top_level++ < kNamed) {
          named_top_level += fmt::format("{}instance {} references VkAccelerationStructureKHR {} (address 0x{:x})",
                                         top_level > 1 ? ", " : "", k, Hex(s.handle), s.device_address);
        }
        continue;
      }
      if (!live.complete) {  // it may be the address of a structure whose address the layer does not know
        unknown = true;
        continue;
      }
      if (bad++ < kNamed) named += fmt::format("{}instance {} references 0x{:x}", bad > 1 ? ", " : "", k, reference);
    }
    if (unknown) CountUnknownState(ctx);
    if (unknown || bad != 0 || top_level != 0) complete = false;
    if (bad > kNamed) named += fmt::format(" (and {} more)", bad - kNamed);
    if (bad != 0) ReportStale(ctx, c, j, bad, named);
    if (top_level > kNamed) named_top_level += fmt::format(" (and {} more)", top_level - kNamed);
    if (top_level != 0) ReportTopLevel(ctx, c, j, top_level, named_top_level);
  }
  if (referenced && complete) {
    for (const Referenced& r : first) {
      if (r.structure < 0) continue;
      const AccelerationStructureState& s = *live.structures[static_cast<std::size_t>(r.structure)];
      referenced->structures.push_back(ReferencedStructures::Referenced{s.handle, s.serial});
    }
  }
  if (!per_structure) return complete;
  // Each referenced structure once, named by the first instance that references it.
  uint32_t findings = 0;
  for (const Referenced& r : first) {
    if (r.structure < 0) continue;
    const auto k = static_cast<std::size_t>(r.structure);
    const std::shared_ptr<const AccelerationStructureState>& structure = live.structures[k];
    // Several bound structures at this address: which one the instance meant, and so its activity, is not known.
    if (k < c.activities.size() && c.activities[k] && live.shared[k]) {
      CountUnknownState(ctx);
    } else if (k < c.activities.size() && c.activities[k] && c.activities[k]->NoActivePrimitive()) {
      ReportDegenerateInstance(ctx, c, r.geometry, r.instance, structure->handle, structure->device_address);
    }
    if (findings >= kMaxStructureFindings) continue;
    findings += CheckReferenced(ctx, c, *log, info, r, k);
  }
  return complete;
}

}  // namespace asval
