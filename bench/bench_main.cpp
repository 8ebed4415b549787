// Google Benchmark suite: the activity pass per format, the builds per scene / size / mode / threads,
// and (with Embree installed) Embree side by side. Counters: Mprims/s (items_per_second), SAH, SAH over
// Embree rtcBuildBVH HIGH (binary, leaves <= 8; set ASVAL_BENCH_ANCHOR=1, it is slow), peak B/prim.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <map>
#include <string>

#include "alloc_counter.h"
#include "asval/builder/classify.h"
#include "asval/builder/vertex_format.h"
#include "bench_common.h"
#include "embree_anchor.h"
#include "format_encode.h"

using namespace asval::builder;

namespace {

constexpr uint32_t kMillion = 1000000;

void BM_Activity(benchmark::State& state, VkFormat format, const char* sceneName) {
    const scenes::Scene& s = bench::CachedScene(sceneName, kMillion);
    const bench::EncodedScene e = bench::Encode(s, format);
    ActivityRecord record;
    for (auto _ : state) {
        const ClassifyResult r = ClassifyTriangles(e.view, &record, nullptr);
        benchmark::DoNotOptimize(r.active);
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * s.triangles);
    state.counters["kept_B_per_prim"] = double(record.HeapBytes()) / s.triangles;
}

double AnchorSah(const std::string& scene, uint32_t n) {
    static std::map<std::pair<std::string, uint32_t>, double> cache;
    const char* want = std::getenv("ASVAL_BENCH_ANCHOR");
    if (!anchor::Available() || !want || want[0] != '1') return 0;
    auto it = cache.find({scene, n});
    if (it != cache.end()) return it->second;
    const double sah = anchor::UserBvh(bench::CachedScene(scene, n), 2, 2).sah;
    cache[{scene, n}] = sah;
    return sah;
}

void BM_Build(benchmark::State& state, const char* sceneName, BuildMode mode) {
    const uint32_t n = uint32_t(state.range(0));
    BuildOptions o;
    o.mode = mode;
    o.threads = uint32_t(state.range(1));
    const scenes::Scene& s = bench::CachedScene(sceneName, n);
    bench::BuildRun last;
    double total = 0;
    for (auto _ : state) {
        last = bench::RunBuild(s, o);
        state.SetIterationTime(last.seconds);
        total += last.seconds;
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * s.triangles);
    state.counters["SAH"] = last.sah;
    const double anchorSah = AnchorSah(sceneName, n);
    if (anchorSah > 0) state.counters["xHIGH"] = last.sah / anchorSah;
    state.counters["peak_B_per_prim"] = double(last.peakBytes) / s.triangles;
    state.counters["prepare_share"] = last.prepareSeconds / last.seconds;
    state.counters["depth"] = last.stats.maxDepth;
    state.counters["cpu_Mprims_per_s"] = s.triangles / last.cpuSeconds * 1e-6;
    state.counters["split_refs"] = last.stats.splitReferences;
}

void BM_EmbreeCommit(benchmark::State& state, const char* sceneName, int quality) {
    const uint32_t n = uint32_t(state.range(0));
    const scenes::Scene& s = bench::CachedScene(sceneName, n);
    for (auto _ : state) state.SetIterationTime(anchor::SceneCommit(s, quality, int(state.range(1))));
    state.SetItemsProcessed(int64_t(state.iterations()) * s.triangles);
}

void Register() {
    for (const VertexFormatInfo* f = VertexFormatsBegin(); f != VertexFormatsEnd(); ++f)
        for (const char* scene : {"sphere", "uniform"}) {
            const std::string name = std::string("Activity/") + scene + "/fmt" + std::to_string(int(f->format)) +
                                     (f->mandatory ? "/mandatory" : "/optional");
            benchmark::RegisterBenchmark(name.c_str(), BM_Activity, f->format, scene)->Unit(benchmark::kMillisecond);
        }
    for (const char* scene : {"uniform", "sphere", "terrain", "clustered"}) {
        for (auto [mode, label] : {std::pair{BuildMode::BinnedSah, "sah"}, std::pair{BuildMode::Lbvh, "lbvh"}}) {
            const std::string name = std::string("Build/") + scene + "/" + label;
            benchmark::RegisterBenchmark(name.c_str(), BM_Build, scene, mode)
                ->ArgsProduct({{10000, 100000, kMillion}, {1, 2}})
                ->ArgNames({"n", "threads"})
                ->UseManualTime()
                ->Unit(benchmark::kMillisecond);
        }
        if (anchor::Available()) {
            for (auto [q, label] : {std::pair{0, "LOW"}, std::pair{1, "MEDIUM"}, std::pair{2, "HIGH"}}) {
                const std::string name = std::string("Embree/") + scene + "/commit_" + label;
                benchmark::RegisterBenchmark(name.c_str(), BM_EmbreeCommit, scene, q)
                    ->ArgsProduct({{10000, 100000, kMillion}, {1, 2}})
                    ->ArgNames({"n", "threads"})
                    ->UseManualTime()
                    ->Unit(benchmark::kMillisecond);
            }
        }
    }
}

}  // namespace

int main(int argc, char** argv) {
    Register();
    benchmark::Initialize(&argc, argv);
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
