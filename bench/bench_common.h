// Scene cache and one timed build, shared by the Google Benchmark suite and the sweep tool.
#pragma once

#include <cstdint>
#include <string>

#include "asval/builder/bvh.h"
#include "scenes.h"

namespace bench {

const scenes::Scene& CachedScene(const std::string& name, uint32_t triangles);

struct BuildRun {
    double seconds = 0;          // AppendTriangles + SplitLargeTriangles + BuildBvh, wall clock
    double cpuSeconds = 0;       // the same span in process CPU time (robust to other load on the machine)
    double prepareSeconds = 0;   // AppendTriangles alone (classification + conservative boxes)
    double sah = 0;
    size_t peakBytes = 0;        // heap peak above the scene itself: every byte allocated, touched or not
    size_t peakResidentBytes = 0;  // resident (RSS) peak above the start of the build (0: unsupported)
    asval::builder::BuildStats stats;
};

BuildRun RunBuild(const scenes::Scene& s, const asval::builder::BuildOptions& o);

}  // namespace bench
