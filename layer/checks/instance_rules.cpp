#include "instance_rules.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "build_report.h"
#include "structure_memory.h"

namespace asval {

namespace {

constexpr std::size_t kNamed = 4;          // references named in a message; the rest are counted
constexpr uint32_t kMaxStructureFindings = 16;  // per build and rule: enough to show the pattern
constexpr VkDeviceSize kInstanceBytes = sizeof(VkAccelerationStructureInstanceKHR);
constexpr std::size_t kReferenceOffset = offsetof(VkAccelerationStructureInstanceKHR, accelerationStructureReference);

// A live structure the build's instances reference, and the first instance that does (for messages).
struct Referenced {
  std::ptrdiff_t structure;  // index in the live snapshot
  uint32_t geometry;
  uint32_t instance;
};

void Report(const CheckContext& ctx, const InstanceReferenceCheck& c, const char* rule,
            VkAccelerationStructureKHR referenced, const std::string& message) {
  const char* command = OpCommandName(c.build.command);
  ctx.reporter.Report(Severity::kError, fmt::format("VUID-{}-{}", command, rule), Location(command),
                      {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, c.build.command_buffer),
                       Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, c.dst),
                       Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, referenced)},
                      message);
}

[[gnu::cold]] void ReportStale(const CheckContext& ctx, const InstanceReferenceCheck& c, uint32_t geometry,
                               uint64_t bad, const std::string& named) {
  Report(ctx, c, "pInfos-06707", VK_NULL_HANDLE,
         fmt::format("{}: builds top-level {}; on execution, geometry {}: {} instance(s) reference no acceleration "
                     "structure that was alive when the build was submitted (not 0 and not an address "
                     "vkGetAccelerationStructureDeviceAddressKHR returned for a live structure): {}.",
                     DescribeOrigin(c.build), Hex(c.dst), geometry, bad, named));
}

// "geometry 0, instance 3 references VkAccelerationStructureKHR 0x... (address 0x...)".
std::string Referencing(const Referenced& r, const AccelerationStructureState& s) {
  return fmt::format("geometry {}, instance {} references VkAccelerationStructureKHR {} (address 0x{:x})", r.geometry,
                     r.instance, Hex(s.handle), s.device_address);
}

// pInfos-03709: the buffer the referenced structure was created on is bound to device memory when the build
// executes. Judged on the structure the snapshot saw, if it is still that structure now (destroyed since: nothing
// concluded).
[[gnu::cold]] void ReportStorageLost(const CheckContext& ctx, const InstanceReferenceCheck& c, const Referenced& r,
                                     const AccelerationStructureState& s, const char* why) {
  Report(ctx, c, "pInfos-03709", s.handle,
         fmt::format("{}: builds top-level {}; on execution, {}, whose buffer (VkBuffer {}) {}.",
                     DescribeOrigin(c.build), Hex(c.dst), Referencing(r, s), Hex(s.buffer), why));
}

bool StillTheSame(const DeviceState& state, const AccelerationStructureState& s) {
  std::optional<std::shared_ptr<const AccelerationStructureState>> now = state.acceleration_structures.find(s.handle);
  return now && *now && (*now)->device_address == s.device_address && (*now)->buffer_id == s.buffer_id;
}

// The rules about one structure the build's instances reference: its storage (03709) and, for a command of
// several infos, the command's other destinations (None-03407, dstAccelerationStructure-03706). Returns the
// findings made (for the cap).
uint32_t CheckReferenced(const CheckContext& ctx, const InstanceReferenceCheck& c, const CaptureLog& log,
                         const CapturedInfo& info, const Referenced& r,
                         const std::shared_ptr<const AccelerationStructureState>& structure) {
  const AccelerationStructureState& s = *structure;
  uint32_t findings = 0;
  std::shared_ptr<const BufferState> buffer;
  const bool known = s.buffer_id != 0 && StillTheSame(ctx.state, s);
  if (!known) {
    CountUnknownState(ctx);
  } else {
    buffer = BufferOfStructure(ctx.state, s);
    if (!buffer) {
      ReportStorageLost(ctx, c, r, s, "was destroyed");
      ++findings;
    } else if (!buffer->bound || buffer->memory == VK_NULL_HANDLE) {
      ReportStorageLost(ctx, c, r, s, buffer->memory_freed ? "has had its memory freed" : "is bound to no memory");
      ++findings;
      buffer.reset();
    }
  }
  // The whole structure: which of its bytes the build reads is the driver's business.
  const std::optional<MemorySpan> referenced_span =
      buffer ? StructureMemory{structure, buffer}.Span() : std::nullopt;
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
    if (!referenced_span || other.accessed.memory == VK_NULL_HANDLE) {
      CountUnknownState(ctx);
      continue;
    }
    if (!Overlaps(*referenced_span, other.accessed)) continue;
    const VkDeviceSize from = std::max(referenced_span->begin, other.accessed.begin);
    const VkDeviceSize to = std::min(referenced_span->end, other.accessed.end);
    Report(ctx, c, "dstAccelerationStructure-03706", s.handle,
           fmt::format("{}: builds top-level {}; on execution, {}, whose memory overlaps the bytes this command writes "
                       "for pInfos[{}].dstAccelerationStructure (VkAccelerationStructureKHR {}): {} bytes at "
                       "[0x{:x}, 0x{:x}) of VkDeviceMemory {}.",
                       DescribeOrigin(c.build), Hex(c.dst), Referencing(r, s), other.element, Hex(other.handle),
                       to - from, from, to, Hex(other.accessed.memory)));
    ++findings;
  }
  return findings;
}

}  // namespace

void CheckInstanceReferences(const CheckContext& ctx, const InstanceReferenceCheck& c) {
  const CaptureLog* log = c.log.get();
  const CapturedInfo* readable = log ? log->Readable(c.info) : nullptr;
  if (!readable || !c.live) {
    CountUnknownState(ctx);
    return;
  }
  const CapturedInfo& info = *readable;
  const LiveStructureAddresses& live = *c.live;
  std::vector<Referenced> referenced;  // per completed build, not per recorded call
  for (uint32_t j = 0; j < info.geometry_count; ++j) {
    const CapturedGeometry& g = log->geometries[info.first_geometry + j];
    if (g.type != VK_GEOMETRY_TYPE_INSTANCES_KHR || g.range.primitiveCount == 0 || !g.data.present) continue;
    const uint8_t* bytes = log->Bytes(g.data);
    uint64_t bad = 0;
    bool unknown = false;
    std::string named;
    for (uint32_t k = 0; k < g.range.primitiveCount; ++k) {
      uint64_t reference = 0;
      std::memcpy(&reference, bytes + k * kInstanceBytes + kReferenceOffset, sizeof(reference));
      if (reference == 0) continue;  // an inactive instance
      const std::ptrdiff_t structure = live.Find(reference);
      if (structure >= 0) {
        if (referenced.empty() || referenced.back().structure != structure) {
          referenced.push_back(Referenced{structure, j, k});
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
    if (bad > kNamed) named += fmt::format(" (and {} more)", bad - kNamed);
    if (bad != 0) ReportStale(ctx, c, j, bad, named);
  }
  // Each referenced structure once, named by the first instance that references it.
  std::stable_sort(referenced.begin(), referenced.end(),
                   [](const Referenced& a, const Referenced& b) { return a.structure < b.structure; });
  referenced.erase(std::unique(referenced.begin(), referenced.end(),
                               [](const Referenced& a, const Referenced& b) { return a.structure == b.structure; }),
                   referenced.end());
  uint32_t findings = 0;
  for (const Referenced& r : referenced) {
    findings += CheckReferenced(ctx, c, *log, info, r, live.structures[static_cast<std::size_t>(r.structure)]);
    if (findings >= kMaxStructureFindings) break;
  }
}

}  // namespace asval
