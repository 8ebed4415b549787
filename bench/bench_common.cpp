#include "bench_common.h"

#include <chrono>
#include <ctime>
#include <map>
#include <memory>

#include "alloc_counter.h"
#include "resident_peak.h"
#include "asval/builder/bvh_triangles.h"

namespace bench {

const scenes::Scene& CachedScene(const std::string& name, uint32_t triangles) {
    static std::map<std::pair<std::string, uint32_t>, std::unique_ptr<scenes::Scene>> cache;
    auto& slot = cache[{name, triangles}];
    if (!slot) slot = std::make_unique<scenes::Scene>(scenes::ByName(name, triangles));
    return *slot;
}

BuildRun RunBuild(const scenes::Scene& s, const asval::builder::BuildOptions& o) {
    using clock = std::chrono::steady_clock;
    BuildRun r;
    const size_t residentBefore = resident::StartSpan();
    alloccount::ResetPeak();
    const size_t before = alloccount::CurrentBytes();
    timespec c0, c1;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c0);
    const auto t0 = clock::now();
    asval::builder::BuildInput in;
    const asval::builder::TriangleGeometryView view = scenes::View(s);
    asval::builder::AppendTriangles(view, true, 0, &in);
    const uint32_t added = asval::builder::SplitLargeTriangles(&view, 1, o, &in);
    const auto t1 = clock::now();
    asval::builder::Bvh bvh = asval::builder::BuildBvh(std::move(in), o);
    const auto t2 = clock::now();
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c1);
    r.cpuSeconds = double(c1.tv_sec - c0.tv_sec) + 1e-9 * double(c1.tv_nsec - c0.tv_nsec);
    bvh.stats.splitReferences = added;
    r.peakBytes = alloccount::PeakBytes() - before;
    const size_t residentPeak = resident::PeakSinceStart();
    r.peakResidentBytes = residentPeak > residentBefore ? residentPeak - residentBefore : 0;
    r.seconds = std::chrono::duration<double>(t2 - t0).count();
    r.prepareSeconds = std::chrono::duration<double>(t1 - t0).count();
    r.sah = asval::builder::SahCost(bvh);
    r.stats = bvh.stats;
    return r;
}

}  // namespace bench
