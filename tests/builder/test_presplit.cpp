// Spatial pre-splitting: only where the scene needs it, never a hole in the coverage of a triangle.
#include <catch2/catch_test_macros.hpp>

#include <cmath>
#include <map>
#include <vector>

#include "asval/builder/bvh_triangles.h"
#include "bvh_checks.h"
#include "exact.h"
#include "scenes.h"
#include "test_support.h"

using namespace asval::builder;

namespace {

// Leaf boxes per id.
std::map<uint32_t, std::vector<const BvhNode*>> LeavesById(const Bvh& bvh) {
    std::map<uint32_t, std::vector<const BvhNode*>> m;
    bvhcheck::ForEachLeafRef(bvh, [&](const BvhNode& leaf, uint32_t id) { m[id].push_back(&leaf); });
    return m;
}

}  // namespace

TEST_CASE("automatic spatial splits: none on meshes, some on the clustered scene", "[bvh][presplit]") {
    BuildOptions o;
    for (const char* name : {"uniform", "sphere", "terrain"}) {
        const scenes::Scene s = scenes::ByName(name, 20000);
        const TriangleGeometryView v = scenes::View(s);
        const Bvh bvh = BuildTriangleBvh(&v, 1, true, o);
        INFO(name);
        CHECK(bvh.stats.splitReferences == 0);
        CHECK(!bvh.stats.usedSpatialSplits);
    }
    const scenes::Scene s = scenes::Clustered(20000, 9);
    const TriangleGeometryView v = scenes::View(s);
    const Bvh split = BuildTriangleBvh(&v, 1, true, o);
    CHECK(split.stats.usedSpatialSplits);
    CHECK(split.stats.splitReferences > 0);
    CHECK(split.stats.splitReferences <= uint32_t(20000 * o.splitBudget));
    BuildOptions off = o;
    off.spatialSplits = SpatialSplits::Off;
    const Bvh plain = BuildTriangleBvh(&v, 1, true, off);
    CHECK(SahCost(split) < 0.6 * SahCost(plain));  // the reason splits exist
    const auto report = bvhcheck::CheckTree(split, {}, 8, false);
    INFO(report.first);
    CHECK(report.violations == 0);
}

TEST_CASE("split pieces cover the whole triangle: vertices exactly, interior points densely", "[bvh][presplit][property]") {
    testsupport::Rng rng(31);
    uint64_t misses = 0, checked = 0;
    const uint64_t rounds = 20 * testsupport::TestScale();
    for (uint64_t round = 0; round < rounds; ++round) {
        // Long slivers among small triangles, optionally under a random transform.
        std::vector<float> v;
        const uint32_t n = 2000;
        for (uint32_t t = 0; t < n; ++t) {
            const bool sliver = t % 50 == 0;
            const double c[3] = {rng.Unit() * 100, rng.Unit() * 100, rng.Unit() * 100};
            for (int k = 0; k < 3; ++k)
                for (int a = 0; a < 3; ++a)
                    v.push_back(float(c[a] + (rng.Unit() - 0.5) * (sliver ? 200.0 : 0.5)));
        }
        float m[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
        const bool transformed = round % 2 == 1;
        if (transformed)
            for (int i = 0; i < 12; ++i) m[i] = float((rng.Unit() * 2 - 1) * (i % 4 == 3 ? 1e4 : 3.0));
        TriangleGeometryView view;
        view.vertexData = v.data();
        view.vertexDataBytes = v.size() * 4;
        view.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
        view.vertexStride = 12;
        view.maxVertex = 3 * n - 1;
        view.range.primitiveCount = n;
        if (transformed) { view.transformData = m; view.transformDataBytes = sizeof m; }
        BuildOptions o;
        o.mode = round % 4 < 2 ? BuildMode::BinnedSah : BuildMode::Lbvh;
        const Bvh bvh = BuildTriangleBvh(&view, 1, true, o);
        REQUIRE(bvh.stats.splitReferences > 0);
        REQUIRE(bvhcheck::CheckTree(bvh, {}, 8, false).violations == 0);
        const auto leaves = LeavesById(bvh);
        for (uint32_t t = 0; t < n; ++t) {
            const auto it = leaves.find(t);
            REQUIRE(it != leaves.end());
            const float* tri = &v[size_t(t) * 9];
            // Vertices: exact, in at least one leaf of this triangle.
            for (int k = 0; k < 3; ++k) {
                bool inside = false;
                for (const BvhNode* leaf : it->second) {
                    bool all = true;
                    for (int a = 0; a < 3 && all; ++a)
                        all = exact::SignAffineMinus(m + 4 * a, tri + 3 * k, leaf->lo[a]) >= 0 &&
                              exact::SignAffineMinus(m + 4 * a, tri + 3 * k, leaf->hi[a]) <= 0;
                    inside |= all;
                }
                ++checked;
                misses += !inside;
            }
            // Interior points (long double, so only a hole larger than ~1e-15 relative can be missed).
            for (int p = 0; p < 8; ++p) {
                long double b0 = rng.Unit(), b1 = rng.Unit();
                if (b0 + b1 > 1) { b0 = 1 - b0; b1 = 1 - b1; }
                const long double b2 = 1 - b0 - b1;
                long double q[3];
                for (int a = 0; a < 3; ++a) {
                    long double x[3];
                    for (int c = 0; c < 3; ++c) x[c] = b0 * tri[c] + b1 * tri[3 + c] + b2 * tri[6 + c];
                    q[a] = (long double)m[4 * a] * x[0] + (long double)m[4 * a + 1] * x[1] + (long double)m[4 * a + 2] * x[2] + m[4 * a + 3];
                }
                bool inside = false;
                for (const BvhNode* leaf : it->second) {
                    bool all = true;
                    for (int a = 0; a < 3 && all; ++a) {
                        const long double tol = 1e-15L * (fabsl(q[a]) + 1);
                        all = q[a] >= leaf->lo[a] - tol && q[a] <= leaf->hi[a] + tol;
                    }
                    inside |= all;
                }
                ++checked;
                misses += !inside;
            }
        }
    }
    CHECK(misses == 0);
    CHECK(checked == rounds * 2000 * 11);
}
