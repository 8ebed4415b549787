#include "capture_notices.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>

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
                    FloatSpacingAt(c.magnitude), c.size));
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

namespace {

// Instances placed so far out that floats there are spaced more than permille / 1000 of the smallest primitive of
// the structure they reference (its activity as of the build's submission: capture = all). Returns the count and
// names the first.
struct FarInstances {
  uint32_t count = 0;
  uint32_t first = 0;
  float translation = 0;
  float smallest = 0;
};

FarInstances FindFarInstances(const InstanceReferenceCheck& build, const uint8_t* records, uint32_t count,
                              uint32_t permille) {
  FarInstances far;
  if (!build.live || build.activities.empty()) return far;
  for (uint32_t k = 0; k < count; ++k) {
    VkAccelerationStructureInstanceKHR instance;
    std::memcpy(&instance, records + k * sizeof(instance), sizeof(instance));
    const std::ptrdiff_t structure = build.live->Find(instance.accelerationStructureReference);
    if (structure < 0) continue;
    const std::shared_ptr<const BuildActivity>& activity = build.activities[static_cast<std::size_t>(structure)];
    if (!activity || activity->status() != BuildActivity::Status::kReady || activity->smallest_primitive() <= 0) {
      continue;
    }
    const float (&m)[3][4] = instance.transform.matrix;
    const float translation = std::max({std::fabs(m[0][3]), std::fabs(m[1][3]), std::fabs(m[2][3])});
    if (!std::isfinite(translation) || !SpacingExceeds(translation, activity->smallest_primitive(), permille)) continue;
    if (far.count++ == 0) {
      far.first = k;
      far.translation = translation;
      far.smallest = activity->smallest_primitive();
    }
  }
  return far;
}

}  // namespace

void ReportInstanceTransforms(const CheckContext& ctx, const InstanceReferenceCheck& build, uint32_t warnings,
                              uint32_t spacing_permille) {
  const CaptureLog* log = build.log.get();
  const CapturedInfo* readable = log ? log->Readable(build.info) : nullptr;
  if (!readable) return;
  const CapturedInfo& info = *readable;
  const Location loc(OpCommandName(build.build.command));
  for (uint32_t j = 0; j < info.geometry_count; ++j) {
    CapturedGeometry g;  // an indirect info's with its range as the device read it
    if (!ExecutedGeometry(*log, info, j, &g)) continue;  // the instance rules counted it
    // Arrays of pointers: their gathered records (a record not followed is zeros: nothing to warn about).
    if (g.type != VK_GEOMETRY_TYPE_INSTANCES_KHR || !g.data.present) continue;
    const uint8_t* bytes = log->Bytes(g.data);
    if (spacing_permille != 0 && !g.reduced) {  // (never reduced: the capture copies when float_spacing is on)
      const FarInstances far = FindFarInstances(build, bytes, g.range.primitiveCount, spacing_permille);
      if (far.count != 0) {
        ctx.reporter.Report(
            Severity::kWarning, kFloatSpacingId, loc,
            {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, build.build.command_buffer),
             Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, build.dst)},
            fmt::format("{}: on execution, geometry {}: {} instance(s) are translated so far that 32-bit floats there "
                        "are spaced more than {}/1000 of the smallest primitive of the structure they reference apart "
                        "(first: instance {}, a translation of magnitude {:g}, where floats are {:g} apart, for a "
                        "smallest primitive of {:g}): hits there are imprecise.",
                        DescribeOrigin(build.build), j, far.count, spacing_permille, far.first, far.translation,
                        FloatSpacingAt(far.translation), far.smallest));
      }
    }
    if (!(warnings & kCaptureWarnNonFiniteTransform)) continue;
    uint32_t count = 0, first = 0;
    int element = -1;
    if (g.reduced) {  // no records here: the dispatch's bits, and its first element per 32 records
      const ReducedGeometry reduced = log->Reduced(g);
      for (uint32_t w = 0; w < ReducedWords(reduced.count); ++w) {
        const uint32_t bits = reduced.Word(ReducedGeometry::kNonFinite, w);
        if (bits == 0) continue;
        if (count == 0) {
          const uint32_t lane_element = reduced.Word(ReducedGeometry::kFirstNonFinite, w);
          first = 32 * w + (lane_element >> 4);
          element = static_cast<int>(lane_element & 15u);
        }
        count += static_cast<uint32_t>(__builtin_popcount(bits));
      }
    }
    for (uint32_t k = 0; k < g.range.primitiveCount && !g.reduced; ++k) {
      // The transform is the record's first member. All finite, nearly always: the inline test, then the element.
      const uint8_t* transform = bytes + k * sizeof(VkAccelerationStructureInstanceKHR);
      if (AllFinite(transform)) continue;
      if (count++ == 0) first = k, element = FirstNonFiniteElement(transform);
    }
    if (count == 0) continue;
    ctx.reporter.Report(Severity::kWarning, kNonFiniteTransformId, loc,
                        {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, build.build.command_buffer),
                         Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, build.dst)},
                        fmt::format("{}: on execution, geometry {}: {} instance(s) have a NaN or infinite element in "
                                    "their transform (first: instance {}, matrix[{}][{}]).",
                                    DescribeOrigin(build.build), j, count, first, element / 4, element % 4));
  }
}

void ReportCaptureBudget(const CheckContext& ctx, uint32_t budget_mb, const char* command) {
  CaptureCounters& counters = ctx.state.capture_counters;
  if (counters.NotCapturedFor(CaptureSkip::kOverBudget) == 0 ||
      counters.budget_reported.exchange(true, std::memory_order_relaxed)) {
    return;
  }
  ctx.reporter.Report(Severity::kWarning, kCaptureBudgetId, Location(command), {},
                      fmt::format("A command buffer's captured build inputs would exceed capture_budget_mb ({} MB): the "
                                  "builds over it are not captured, and the rules that need their bytes are skipped "
                                  "and counted (ASVAL-History-Summary: over_capture_budget_mb). Raise "
                                  "capture_budget_mb to check them. Reported once.",
                                  budget_mb));
}

}  // namespace asval
