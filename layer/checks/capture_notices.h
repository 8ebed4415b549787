#pragma once
// What the execution-time capture tells the app besides rule findings (layer-specific ids):
//   ASVAL-Capture-UndefinedInput (warning): a captured build read a triangle with a NaN Y or Z component while X is
//     not NaN (or an AABB with a NaN outside minX): the specification leaves what the build does undefined.
//   ASVAL-Capture-NonFiniteTransform (warning): a captured geometry transform or instance transform holds a NaN or
//     an infinity.
//   ASVAL-Capture-FloatSpacing (warning, off by default): captured primitives whose coordinates are so large that
//     32-bit floats there are spaced more than capture_float_spacing_permille thousandths of their size apart.
//   ASVAL-Capture-DegenerateInstance (information, capture = all): an instance references a bottom-level structure
//     whose last build has no active primitive.
//   ASVAL-Capture-Budget (warning, once per device): captures were skipped because a recording would have exceeded
//     capture_budget_mb; their rules were skipped and counted.
// The first four follow the capture_warnings setting; each can also be muted by id with message_id_filter. Const:
// reports only.
#include <cstdint>

#include "build_activity.h"
#include "check_context.h"

namespace asval {

inline constexpr const char kUndefinedInputId[] = "ASVAL-Capture-UndefinedInput";
inline constexpr const char kCaptureBudgetId[] = "ASVAL-Capture-Budget";
inline constexpr const char kNonFiniteTransformId[] = "ASVAL-Capture-NonFiniteTransform";
inline constexpr const char kFloatSpacingId[] = "ASVAL-Capture-FloatSpacing";
inline constexpr const char kDegenerateInstanceId[] = "ASVAL-Capture-DegenerateInstance";

// After a captured build's activity was filled (the submission completed).
// `warnings`: the capture_warnings setting (kCaptureWarnUndefinedInput, kCaptureWarnNonFiniteTransform).
void ReportUndefinedInput(const CheckContext& ctx, const BuildActivity& activity, uint32_t warnings);
// After a captured build's activity was filled with the spacing scan (kCaptureWarnFloatSpacing).
void ReportCoarseSpacing(const CheckContext& ctx, const BuildActivity& activity, uint32_t permille);
// A captured top-level build's instance references a structure without active primitive.
void ReportDegenerateInstance(const CheckContext& ctx, const InstanceReferenceCheck& build, uint32_t geometry,
                              uint32_t instance, VkAccelerationStructureKHR referenced, VkDeviceAddress address);
// After a captured top-level build completed: its instances' transforms.
// `warnings`: kCaptureWarnNonFiniteTransform reports non-finite instance transforms; spacing_permille > 0 (the
// float_spacing warning) reports instances translated where floats are coarse for what they reference (needs the
// referenced structures' activity: InstanceReferenceCheck::activities, capture = all).
void ReportInstanceTransforms(const CheckContext& ctx, const InstanceReferenceCheck& build, uint32_t warnings,
                              uint32_t spacing_permille);
// After a build's pre-record: reports the budget once, the first time it was exceeded on this device.
void ReportCaptureBudget(const CheckContext& ctx, uint32_t budget_mb, const char* command);

}  // namespace asval
