#include "capture_notices.h"

#include <fmt/format.h>

#include <cmath>

#include "build_report.h"


namespace asval {

void ReportUndefinedInput(const CheckContext& ctx, const BuildActivity& activity, uint32_t warnings) {
  for (const BuildActivity::UndefinedInput& u : activity.undefined_input()) {
    const OpOrigin& origin = activity.origin();
    if (u.transform_element >= 0 && (warnings & kCaptureWarnNonFiniteTransform)) {
      ctx.reporter.Report(Severity::kWarning, kNonFiniteTransformId, Location(OpCommandName(origin.command)),
                          {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, origin.command_buffer),
                           Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, activity.dst())},
                          fmt::format("{}: on execution, geometry {}: its transform (transformData) has a NaN or "
                                      "infinite element, matrix[{}][{}]: every position it transforms is then NaN or "
                                      "infinite.",
                                      DescribeOrigin(origin), u.geometry, u.transform_element / 4,
                                      u.transform_element % 4));
    }
    if (u.primitives == 0 || !(warnings & kCaptureWarnUndefinedInput)) continue;
    ctx.reporter.Report(
        Severity::kWarning, kUndefinedInputId, Location(OpCommandName(origin.command)),
        {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, origin.command_buffer),
         Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, activity.dst())},
        fmt::format("{}: on execution, geometry {}: {} primitive(s) have a NaN component other than the first (X of a "
                    "vertex, minX of an AABB) while that one is not NaN, for which the specification leaves the "
                    "build's result undefined (first: primitive {}).",
                    DescribeOrigin(origin), u.geometry, u.primitives, u.first_primitive));
  }
}

void ReportCoarseSpacing(const CheckContext& ctx, const BuildActivity& activity, uint32_t permille) {
  for (const BuildActivity::CoarseSpacing& c : activity.coarse_spacing()) {
    const OpOrigin& origin = activity.origin();
    ctx.reporter.Report(
        Severity::kWarning, kFloatSpacingId, Location(OpCommandName(origin.command)),
        {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, origin.command_buffer),
         Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, activity.dst())},
        fmt::format("{}: on execution, geometry {}: {} primitive(s) lie where 32-bit floats are spaced more than "
                    "{}/1000 of their size apart (first: primitive {}, a coordinate of magnitude {:g}, where floats "
                    "are {:g} apart, for a size of {:g}): positions and hits there are imprecise. Move the geometry "
                    "nearer the origin (an instance transform can carry the offset) or raise "
                    "capture_float_spacing_permille.",
                    DescribeOrigin(origin), c.geometry, c.primitives, permille, c.first_primitive, c.magnitude,
                    std::nextafter(c.magnitude, INFINITY) - c.magnitude, c.size));
  }
}

void ReportDegenerateInstance(const CheckContext& ctx, const InstanceReferenceCheck& build, uint32_t geometry,
                              uint32_t instance, VkAccelerationStructureKHR referenced, VkDeviceAddress address) {
  ctx.reporter.Report(Severity::kInfo, kDegenerateInstanceId, Location(OpCommandName(build.build.command)),
                      {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, build.build.command_buffer),
                       Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, build.dst),
                       Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, referenced)},
                      fmt::format("{}: builds top-level {}; on execution, geometry {}, instance {} references "
                                  "VkAccelerationStructureKHR {} (address 0x{:x}), whose last build has no active "
                                  "primitive: the instance is degenerate (nothing in it can be hit).",
                                  DescribeOrigin(build.build), Hex(build.dst), geometry, instance, Hex(referenced),
                                  address));
}

void ReportInstanceTransforms(const CheckContext& ctx, const InstanceReferenceCheck& build) {
  const CaptureLog* log = build.log.get();
  const CapturedInfo* readable = log ? log->Readable(build.info) : nullptr;
  if (!readable) return;
  const CapturedInfo& info = *readable;
  for (uint32_t j = 0; j < info.geometry_count; ++j) {
    const CapturedGeometry& g = log->geometries[info.first_geometry + j];
    if (g.type != VK_GEOMETRY_TYPE_INSTANCES_KHR || !g.data.present || g.array_of_pointers) continue;
    const uint8_t* bytes = log->Bytes(g.data);
    uint32_t count = 0, first = 0;
    int element = -1;
    for (uint32_t k = 0; k < g.range.primitiveCount; ++k) {
      // The transform is the record's first member.
      const int e = FirstNonFiniteElement(bytes + k * sizeof(VkAccelerationStructureInstanceKHR));
      if (e >= 0 && count++ == 0) first = k, element = e;
    }
    if (count == 0) continue;
    ctx.reporter.Report(Severity::kWarning, kNonFiniteTransformId, Location(OpCommandName(build.build.command)),
                        {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, build.build.command_buffer),
                         Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, build.dst)},
                        fmt::format("{}: on execution, geometry {}: {} instance(s) have a NaN or infinite element in "
                                    "their transform (first: instance {}, matrix[{}][{}]).",
                                    DescribeOrigin(build.build), j, count, first, element / 4, element % 4));
  }
}

void ReportCaptureBudget(const CheckContext& ctx, uint32_t budget_mb, const char* command) {
  CaptureCounters& counters = ctx.state.capture_counters;
  if (counters.infos_over_budget.load(std::memory_order_relaxed) == 0 ||
      counters.budget_reported.exchange(true, std::memory_order_relaxed)) {
    return;
  }
  ctx.reporter.Report(Severity::kWarning, kCaptureBudgetId, Location(command), {},
                      fmt::format("A command buffer's captured build inputs would exceed capture_budget_mb ({} MB): the "
                                  "builds over it are not captured, and the rules that need their bytes are skipped "
                                  "and counted (ASVAL-History-Summary). Raise capture_budget_mb to check them. "
                                  "Reported once.",
                                  budget_mb));
}

}  // namespace asval
