// The pre-splitter and the LBVH with threads: the pre-splitter works in fixed chunks (area scans,
// candidates) whose results are combined in chunk order, so its references must not depend on
// BuildOptions::threads; and its pieces must still cover their triangles when several chunks and threads
// are involved.
#include <catch2/catch_test_macros.hpp>

#include <cstring>
#include <map>
#include <vector>

#include "asval/builder/bvh_triangles.h"
#include "bvh_checks.h"
#include "scenes.h"
#include "test_support.h"

using namespace asval::builder;

namespace {

struct Split {
    std::vector<PrimRef> refs;
    uint32_t added = 0;
};

Split RunSplit(const TriangleGeometryView& view, uint32_t threads) {
    BuildOptions o;
    o.threads = threads;
    BuildInput in;
    AppendTriangles(view, true, 0, &in);
    Split s;
    s.added = SplitLargeTriangles(&view, 1, o, &in);
    s.refs = std::move(in.refs);
    return s;
}

bool SameBytes(const std::vector<PrimRef>& a, const std::vector<PrimRef>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(PrimRef)) == 0;
}

}  // namespace

TEST_CASE("pre-split references are identical at 1, 2, 3 and 8 threads", "[presplit][determinism]") {
    // 200k triangles: four area-scan chunks and some hundred splitting chunks.
    const scenes::Scene s = scenes::Clustered(200000, 5);
    const TriangleGeometryView view = scenes::View(s);
    const Split one = RunSplit(view, 1);
    REQUIRE(one.added > 10000);
    REQUIRE(one.refs.size() == s.triangles + one.added);
    for (uint32_t threads : {2u, 3u, 8u}) {
        INFO("threads " << threads);
        const Split other = RunSplit(view, threads);
        CHECK(other.added == one.added);
        CHECK(SameBytes(one.refs, other.refs));
    }
    // And run to run at 2 threads (dynamic chunk claiming must not leak into the order).
    CHECK(SameBytes(RunSplit(view, 2).refs, RunSplit(view, 2).refs));
}

TEST_CASE("pre-split pieces cover every vertex of their triangle at 2 threads, both modes", "[presplit][property]") {
    const scenes::Scene s = scenes::Clustered(120000, 17);
    const TriangleGeometryView view = scenes::View(s);
    for (BuildMode mode : {BuildMode::BinnedSah, BuildMode::Lbvh}) {
        BuildOptions o;
        o.mode = mode;
        o.threads = 2;
        const Bvh bvh = BuildTriangleBvh(&view, 1, true, o);
        REQUIRE(bvh.stats.splitReferences > 0);
        REQUIRE(bvhcheck::CheckTree(bvh, {}, 8, false).violations == 0);
        // Untransformed float vertices are exact, so "inside" is a plain comparison.
        std::vector<std::vector<const BvhNode*>> leaves(s.triangles);
        bvhcheck::ForEachLeafRef(bvh, [&](const BvhNode& leaf, uint32_t id) { leaves[id].push_back(&leaf); });
        uint64_t misses = 0, pieces = 0;
        for (uint32_t t = 0; t < s.triangles; ++t) {
            pieces += leaves[t].size();
            for (int k = 0; k < 3; ++k) {
                const uint32_t vi = s.indices.empty() ? 3 * t + uint32_t(k) : s.indices[3 * size_t(t) + size_t(k)];
                const float* p = &s.vertices[3 * size_t(vi)];
                bool inside = false;
                for (const BvhNode* leaf : leaves[t]) {
                    bool all = true;
                    for (int a = 0; a < 3; ++a) all = all && p[a] >= leaf->lo[a] && p[a] <= leaf->hi[a];
                    inside = inside || all;
                }
                misses += !inside;
            }
        }
        INFO("mode " << int(mode));
        CHECK(misses == 0);
        CHECK(pieces == uint64_t(s.triangles) + bvh.stats.splitReferences);
    }
}

TEST_CASE("LBVH quality: within 1.4x of the binned SAH tree on every scene family", "[bvh][lbvh]") {
    // A broken Morton sort (wrong order, lost references) would still give a sound tree; its SAH would not.
    for (const char* name : {"uniform", "sphere", "terrain", "clustered"}) {
        const scenes::Scene s = scenes::ByName(name, 50000);
        const TriangleGeometryView view = scenes::View(s);
        BuildOptions sah;
        BuildOptions fast;
        fast.mode = BuildMode::Lbvh;
        const double ratio = SahCost(BuildTriangleBvh(&view, 1, true, fast)) / SahCost(BuildTriangleBvh(&view, 1, true, sah));
        INFO(name << " LBVH / SAH = " << ratio);
        CHECK(ratio > 0.95);
        CHECK(ratio < 1.4);
    }
}

TEST_CASE("LBVH: every Morton width gives a sound tree holding each reference once", "[bvh][lbvh]") {
    const scenes::Scene s = scenes::Uniform(30000, 3);
    const TriangleGeometryView view = scenes::View(s);
    BuildInput input;
    AppendTriangles(view, true, 0, &input);
    const auto byId = bvhcheck::RefsById(input);
    for (uint32_t bits : {1u, 2u, 7u, 10u, 11u, 16u, 21u}) {
        BuildOptions o;
        o.mode = BuildMode::Lbvh;
        o.mortonBitsPerAxis = bits;
        o.spatialSplits = SpatialSplits::Off;
        BuildInput copy = input;
        const Bvh bvh = BuildBvh(std::move(copy), o);
        const auto report = bvhcheck::CheckTree(bvh, byId, 8, true);
        INFO("bits " << bits << ": " << report.first);
        CHECK(report.violations == 0);
    }
}
