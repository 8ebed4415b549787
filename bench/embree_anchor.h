// Embree side by side (only when libembree-dev is installed; ASVAL_HAVE_EMBREE).
#pragma once

#include <cstdint>

#include "scenes.h"

namespace anchor {

bool Available();

// SAH (the anchors document's metric, binary, leaves <= 8) of Embree's rtcBuildBVH at `quality`
// (0 LOW, 1 MEDIUM, 2 HIGH with a triangle-clipping splitPrimitive), and its build time in seconds.
struct Result {
    double sah = 0;
    double seconds = 0;
};
Result UserBvh(const scenes::Scene& s, int quality, int threads);

// rtcCommitScene time (seconds) of a triangle scene at `quality` (0 LOW, 1 MEDIUM, 2 HIGH).
double SceneCommit(const scenes::Scene& s, int quality, int threads);

}  // namespace anchor
