#pragma once
// The update rules on primitive activity and index values (pInfos-03663, 03664, 03768), judged when the
// submission that ran the update completes, on the activity the layer classified from the bytes the source's
// last build and the update really read (execution-time capture, layer/capture; BuildActivity, layer/state).
// Const: reports only. Run with the device's capture processing lock held; no other lock of the layer's.
#include "build_activity.h"
#include "check_context.h"

namespace asval {

// Reports what `update` changed against the source's last build: inactive primitives made active (03663),
// active ones made inactive (03664), index values changed (03768), naming the first few primitives. When either
// activity is unknown (not captured, bytes not trusted) the rules are skipped and counted.
// True when the app's callback asked to skip the call (host updates, judged before their downcall).
bool CheckUpdateActivity(const CheckContext& ctx, const ActivityComparison& update);

}  // namespace asval
