#pragma once
// What the execution-time capture tells the app besides rule findings (layer-specific ids):
//   ASVAL-Capture-UndefinedInput (warning): a captured build read a triangle with a NaN Y or Z component while X is
//     not NaN (or an AABB with a NaN outside minX): the specification leaves what the build does undefined.
//   ASVAL-Capture-NonFiniteTransform (warning): a captured geometry transform or instance transform holds a NaN or
//     an infinity.
//   ASVAL-Capture-Budget (warning, once per device): captures were skipped because a recording would have exceeded
//     capture_budget_mb; their rules were skipped and counted.
// Each can be muted by id with message_id_filter. Const: reports only.
#include <cstdint>

#include "build_activity.h"
#include "check_context.h"

namespace asval {

inline constexpr const char kUndefinedInputId[] = "ASVAL-Capture-UndefinedInput";
inline constexpr const char kCaptureBudgetId[] = "ASVAL-Capture-Budget";
inline constexpr const char kNonFiniteTransformId[] = "ASVAL-Capture-NonFiniteTransform";

// After a captured build's activity was filled (the submission completed).
void ReportUndefinedInput(const CheckContext& ctx, const BuildActivity& activity);
// After a captured top-level build completed: its instances' transforms.
void ReportInstanceTransforms(const CheckContext& ctx, const InstanceReferenceCheck& build);
// After a build's pre-record: reports the budget once, the first time it was exceeded on this device.
void ReportCaptureBudget(const CheckContext& ctx, uint32_t budget_mb, const char* command);

}  // namespace asval
