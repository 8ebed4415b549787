// Run time against error: builds every scene with the builder's knobs varied (and Embree's anchors when
// available) and prints one CSV row per point: scene,builder,knobs,threads,seconds,mprims,sah,ratio,peak_bpp.
// ratio = SAH / SAH(Embree rtcBuildBVH HIGH, binary, leaves <= 8); 0 without Embree.
// Usage: asval_builder_sweep [triangles=1000000] [scene ...]  > sweep.csv ; then bench/plot_sweep.py
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench_common.h"
#include "embree_anchor.h"

using namespace asval::builder;

namespace {

// Median of `reps` runs.
bench::BuildRun Measure(const scenes::Scene& s, const BuildOptions& o, int reps) {
    std::vector<bench::BuildRun> runs;
    for (int i = 0; i < reps; ++i) runs.push_back(bench::RunBuild(s, o));
    std::sort(runs.begin(), runs.end(), [](const auto& a, const auto& b) { return a.seconds < b.seconds; });
    return runs[runs.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
    const uint32_t n = argc > 1 ? uint32_t(std::strtoul(argv[1], nullptr, 10)) : 1000000;
    std::vector<std::string> names;
    for (int i = 2; i < argc; ++i) names.push_back(argv[i]);
    if (names.empty()) names = {"uniform", "sphere", "terrain", "clustered"};
    const int reps = n >= 1000000 ? 3 : 5;
    std::printf("scene,builder,knobs,threads,seconds,mprims,sah,ratio,peak_bpp,cpu_seconds\n");
    for (const std::string& name : names) {
        const scenes::Scene& s = bench::CachedScene(name, n);
        double anchorSah = 0;
        if (anchor::Available()) {
            for (int q = 0; q <= 2; ++q) {
                for (int threads : {1, 2}) {
                    if (q == 2 && threads == 1 && n >= 1000000) continue;  // minutes: the 2-thread run gives the SAH
                    const anchor::Result r = anchor::UserBvh(s, q, threads);
                    if (q == 2) anchorSah = r.sah;
                    const char* label = q == 0 ? "embree_user_LOW" : q == 1 ? "embree_user_MEDIUM" : "embree_user_HIGH";
                    std::printf("%s,%s,leaf8,%d,%.6f,%.3f,%.4f,%s,0,0\n", name.c_str(), label, threads, r.seconds,
                                s.triangles / r.seconds * 1e-6, r.sah, "nan");
                    std::fflush(stdout);
                }
            }
            for (int q = 0; q <= 1; ++q)
                for (int threads : {1, 2}) {
                    const double sec = anchor::SceneCommit(s, q, threads);
                    std::printf("%s,%s,bvh8,%d,%.6f,%.3f,0,0,0,0\n", name.c_str(), q == 0 ? "embree_commit_LOW" : "embree_commit_MEDIUM",
                                threads, sec, s.triangles / sec * 1e-6);
                }
        }
        auto row = [&](const char* builder, const std::string& knobs, const BuildOptions& o) {
            const bench::BuildRun r = Measure(s, o, reps);
            std::printf("%s,%s,%s,%u,%.6f,%.3f,%.4f,%.4f,%.1f,%.6f\n", name.c_str(), builder, knobs.c_str(), o.threads,
                        r.seconds, s.triangles / r.seconds * 1e-6, r.sah, anchorSah > 0 ? r.sah / anchorSah : 0.0,
                        double(r.peakBytes) / s.triangles, r.cpuSeconds);
            std::fflush(stdout);
        };
        for (uint32_t threads : {1u, 2u}) {
            BuildOptions o;
            o.threads = threads;
            row("asval_default", "bins16_leaf8", o);
        }
        for (float budget : {0.0f, 0.1f, 0.25f, 0.6f}) {
            BuildOptions o;
            o.splitBudget = budget;
            if (budget == 0) o.spatialSplits = SpatialSplits::Off;
            char knobs[64];
            std::snprintf(knobs, sizeof knobs, "bins16_leaf8_split%.2f", double(budget));
            row("asval_sah", knobs, o);
        }
        for (float factor : {0.25f, 2.0f}) {
            BuildOptions o;
            o.splitFactor = factor;
            char knobs[64];
            std::snprintf(knobs, sizeof knobs, "bins16_leaf8_factor%.2f", double(factor));
            row("asval_sah", knobs, o);
        }
        for (uint32_t bins : {4u, 8u, 32u, 64u}) {
            BuildOptions o;
            o.bins = bins;
            row("asval_sah", "bins" + std::to_string(bins) + "_leaf8", o);
        }
        for (uint32_t leaf : {1u, 2u, 4u}) {
            BuildOptions o;
            o.maxLeafSize = leaf;
            row("asval_sah", "bins16_leaf" + std::to_string(leaf), o);
        }
        for (uint32_t bits : {8u, 10u, 16u, 21u}) {
            BuildOptions o;
            o.mode = BuildMode::Lbvh;
            o.mortonBitsPerAxis = bits;
            row("asval_lbvh", "morton" + std::to_string(3 * bits) + "_leaf8", o);
        }
    }
    return 0;
}
