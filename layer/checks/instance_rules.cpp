#include "instance_rules.h"

#include <fmt/format.h>

#include <cstring>
#include <string>

#include "build_report.h"

namespace asval {

namespace {

constexpr std::size_t kNamed = 4;  // references named in a message; the rest are counted
constexpr VkDeviceSize kInstanceBytes = sizeof(VkAccelerationStructureInstanceKHR);
constexpr std::size_t kReferenceOffset = offsetof(VkAccelerationStructureInstanceKHR, accelerationStructureReference);

[[gnu::cold]] void Report(const CheckContext& ctx, const InstanceReferenceCheck& c, uint32_t geometry, uint64_t bad,
                          const std::string& named) {
  const char* command = OpCommandName(c.build.command);
  const std::string message = fmt::format(
      "{}: builds top-level {}; on execution, geometry {}: {} instance(s) reference no acceleration structure that "
      "was alive when the build was submitted (not 0 and not an address vkGetAccelerationStructureDeviceAddressKHR "
      "returned for a live structure): {}.",
      DescribeOrigin(c.build), Hex(c.dst), geometry, bad, named);
  ctx.reporter.Report(Severity::kError, fmt::format("VUID-{}-pInfos-06707", command), Location(command),
                      {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, c.build.command_buffer),
                       Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, c.dst)},
                      message);
}

}  // namespace

void CheckInstanceReferences(const CheckContext& ctx, const InstanceReferenceCheck& c) {
  const CaptureLog* log = c.log.get();
  const CapturedInfo* readable = log ? log->Readable(c.info) : nullptr;
  if (!readable || !c.live) {
    ctx.state.checks_skipped_unknown_state.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  const CapturedInfo& info = *readable;
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
      if (reference == 0 || c.live->Contains(reference)) continue;
      if (!c.live->complete) {  // it may be the address of a structure whose address the layer does not know
        unknown = true;
        continue;
      }
      if (bad++ < kNamed) named += fmt::format("{}instance {} references 0x{:x}", bad > 1 ? ", " : "", k, reference);
    }
    if (unknown) ctx.state.checks_skipped_unknown_state.fetch_add(1, std::memory_order_relaxed);
    if (bad > kNamed) named += fmt::format(" (and {} more)", bad - kNamed);
    if (bad != 0) Report(ctx, c, j, bad, named);
  }
}

}  // namespace asval
