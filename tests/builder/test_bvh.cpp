// BVH build: structure, stress inputs (T1, T2, T4, T5, T7, T9, N1, N2, I3), determinism across runs and
// thread counts, both modes.
#include <catch2/catch_test_macros.hpp>

#include <cfloat>
#include <cmath>
#include <cstring>

#include "asval/builder/bvh.h"
#include "asval/builder/bvh_triangles.h"
#include "bvh_checks.h"
#include "scenes.h"
#include "test_support.h"

using namespace asval::builder;

namespace {

struct Built {
    BuildInput input;  // copy of the input (refs), kept for checking
    Bvh bvh;
};

Built BuildFrom(const TriangleGeometryView& v, const BuildOptions& o, bool allowUpdate = true) {
    Built b;
    AppendTriangles(v, allowUpdate, 0, &b.input);
    BuildInput copy = b.input;
    b.bvh = BuildBvh(std::move(copy), o);
    return b;
}

void RequireSound(const Built& b, uint32_t maxLeaf = 8) {
    const auto report = bvhcheck::CheckTree(b.bvh, bvhcheck::RefsById(b.input), maxLeaf, true);
    INFO(report.first);
    REQUIRE(report.violations == 0);
}

TriangleGeometryView ViewOf(const std::vector<float>& v) {
    TriangleGeometryView view;
    view.vertexData = v.data();
    view.vertexDataBytes = v.size() * 4;
    view.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    view.vertexStride = 12;
    view.maxVertex = uint32_t(v.size() / 3 - 1);
    view.range.primitiveCount = uint32_t(v.size() / 9);
    return view;
}

const BuildOptions kModes[] = {
    {BuildMode::BinnedSah, 16, 8, 10, SpatialSplits::Off, 0.25f, 4.0f, 1},
    {BuildMode::BinnedSah, 16, 8, 10, SpatialSplits::Off, 0.25f, 4.0f, 2},
    {BuildMode::Lbvh, 16, 8, 10, SpatialSplits::Off, 0.25f, 4.0f, 1},
    {BuildMode::BinnedSah, 4, 1, 10, SpatialSplits::Off, 0.25f, 4.0f, 1},
    {BuildMode::Lbvh, 16, 4, 21, SpatialSplits::Off, 0.25f, 4.0f, 1},
};

}  // namespace

TEST_CASE("scene families build sound trees in every mode", "[bvh]") {
    for (const char* name : {"uniform", "sphere", "terrain", "clustered"}) {
        const scenes::Scene s = scenes::ByName(name, 20000);
        for (const BuildOptions& o : kModes) {
            INFO(name << " mode " << int(o.mode) << " bins " << o.bins << " leaf " << o.maxLeafSize << " threads " << o.threads);
            const Built b = BuildFrom(scenes::View(s), o);
            RequireSound(b, o.maxLeafSize);
            const double sah = SahCost(b.bvh);
            CHECK(std::isfinite(sah));
            CHECK(sah > 1.0);
        }
    }
}

TEST_CASE("output is identical across runs and at 1 and 2 threads", "[bvh][determinism]") {
    const scenes::Scene s = scenes::Clustered(150000, 11);
    BuildOptions o;
    o.threads = 1;
    const Built a = BuildFrom(scenes::View(s), o);
    o.threads = 2;
    const Built b = BuildFrom(scenes::View(s), o);
    const Built c = BuildFrom(scenes::View(s), o);
    REQUIRE(a.bvh.nodes.size() == b.bvh.nodes.size());
    CHECK(std::memcmp(a.bvh.nodes.data(), b.bvh.nodes.data(), a.bvh.nodes.size() * sizeof(BvhNode)) == 0);
    CHECK(a.bvh.primIds == b.bvh.primIds);
    CHECK(std::memcmp(b.bvh.nodes.data(), c.bvh.nodes.data(), b.bvh.nodes.size() * sizeof(BvhNode)) == 0);
    o.mode = BuildMode::Lbvh;
    const Built d = BuildFrom(scenes::View(s), o), e = BuildFrom(scenes::View(s), o);
    CHECK(std::memcmp(d.bvh.nodes.data(), e.bvh.nodes.data(), d.bvh.nodes.size() * sizeof(BvhNode)) == 0);
    // With spatial splits (the clustered scene triggers them), at 1 and 2 threads.
    const TriangleGeometryView view = scenes::View(s);
    BuildOptions split;
    split.threads = 1;
    const Bvh f = BuildTriangleBvh(&view, 1, true, split);
    split.threads = 2;
    const Bvh g = BuildTriangleBvh(&view, 1, true, split);
    CHECK(f.stats.usedSpatialSplits);
    REQUIRE(f.nodes.size() == g.nodes.size());
    CHECK(std::memcmp(f.nodes.data(), g.nodes.data(), f.nodes.size() * sizeof(BvhNode)) == 0);
    CHECK(f.primIds == g.primIds);
}

TEST_CASE("T1/T2: inactive and undefined-NaN triangles stay out; no NaN reaches any node", "[bvh][T1][T2]") {
    std::vector<float> v;
    testsupport::Rng rng(5);
    for (int t = 0; t < 5000; ++t)
        for (int k = 0; k < 9; ++k) v.push_back(float(rng.Unit()));
    for (int t = 0; t < 5000; t += 10) v[size_t(9 * t)] = NAN;            // X NaN: inactive
    for (int t = 5; t < 5000; t += 10) v[size_t(9 * t + 4)] = NAN;        // Y NaN: undefined
    for (const BuildOptions& o : kModes) {
        const Built b = BuildFrom(ViewOf(v), o);
        CHECK(b.input.excludedInactive == 500);
        CHECK(b.input.excludedUndefined == 500);
        CHECK(b.bvh.stats.references == 4000);
        RequireSound(b, o.maxLeafSize);
    }
}

TEST_CASE("T4: inf and huge coordinates are kept, bounded leaves, no NaN, finite SAH", "[bvh][T4]") {
    std::vector<float> v;
    testsupport::Rng rng(6);
    const float specials[] = {INFINITY, -INFINITY, FLT_MAX, -FLT_MAX, 1e30f, -1.844e18f};
    for (int t = 0; t < 20000; ++t)
        for (int k = 0; k < 9; ++k) v.push_back(float(rng.Unit()));
    for (int t = 0; t < 20000; t += 100) v[size_t(9 * t + rng.Below(9))] = specials[rng.Below(6)];
    for (const BuildOptions& o : kModes) {
        const Built b = BuildFrom(ViewOf(v), o);
        CHECK(b.bvh.stats.references == 20000);
        CHECK(b.input.infiniteBoxes > 0);
        RequireSound(b, o.maxLeafSize);
        CHECK(std::isfinite(SahCost(b.bvh)));
    }
}

TEST_CASE("T5/T7: degenerate triangles kept only with ALLOW_UPDATE; same-index ones always dropped", "[bvh][T5][T7]") {
    const float v[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 2, 2};
    const uint32_t idx[] = {0, 1, 2, 3, 3, 3 /* same index */, 0, 1, 1 /* same index */};
    float point[] = {5, 5, 5, 5, 5, 5, 5, 5, 5};
    TriangleGeometryView view;
    view.vertexData = v;
    view.vertexDataBytes = sizeof v;
    view.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    view.vertexStride = 12;
    view.maxVertex = 3;
    view.indexType = VK_INDEX_TYPE_UINT32;
    view.indexData = idx;
    view.indexDataBytes = sizeof idx;
    view.range.primitiveCount = 3;
    BuildInput in;
    AppendTriangles(view, true, 0, &in);
    CHECK(in.refs.size() == 1);
    CHECK(in.excludedSameIndex == 2);
    BuildInput kept, dropped;
    AppendTriangles(ViewOf(std::vector<float>(point, point + 9)), true, 0, &kept);
    AppendTriangles(ViewOf(std::vector<float>(point, point + 9)), false, 0, &dropped);
    CHECK(kept.refs.size() == 1);
    CHECK(dropped.refs.empty());
    CHECK(dropped.excludedDegenerate == 1);
}

TEST_CASE("N1: pathological geometry keeps leaves <= 8 and depth <= 64", "[bvh][N1][T9]") {
    testsupport::Rng rng(8);
    std::vector<std::pair<const char*, std::vector<float>>> cases;
    std::vector<float> same(9 * 30000, 0.25f);  // every triangle at one point (degenerate, kept: ALLOW_UPDATE)
    cases.push_back({"one point", same});
    std::vector<float> copies;
    for (int t = 0; t < 30000; ++t) copies.insert(copies.end(), {0, 0, 0, 1, 0, 0, 0, 1, 0});
    cases.push_back({"copies of one triangle", copies});
    std::vector<float> far, mixed, sub, exp2;
    for (int t = 0; t < 30000; ++t) {
        const float off = (t & 1) ? 1e12f : 0.0f;
        const float scale = (t & 1) ? 1e6f : 1e-6f;
        for (int k = 0; k < 9; ++k) {
            far.push_back(off + float(rng.Unit()));
            mixed.push_back(scale * float(rng.Unit() - 0.5));
            uint32_t bits = 1 + rng.Below(0x7FFFFF);  // subnormals: distinct, never flushed
            float f;
            std::memcpy(&f, &bits, 4);
            sub.push_back(f);
            exp2.push_back(std::ldexp(1.0f, -int(t % 120)) * float(rng.Unit()));  // exponentially nested
        }
    }
    cases.push_back({"two clusters 1e12 apart", far});
    cases.push_back({"mixed 1e-6 / 1e6", mixed});
    cases.push_back({"subnormal scene", sub});
    cases.push_back({"exponentially nested", exp2});
    for (auto& [name, v] : cases) {
        for (const BuildOptions& o : kModes) {
            INFO(name << " mode " << int(o.mode) << " leaf " << o.maxLeafSize);
            const Built b = BuildFrom(ViewOf(v), o);
            CHECK(b.bvh.stats.references == 30000);
            RequireSound(b, o.maxLeafSize);
        }
    }
}

TEST_CASE("N2: 0, 1 and 2 primitives, and all inactive, give valid trees", "[bvh][N2]") {
    for (const BuildOptions& o : kModes) {
        BuildInput empty;
        const Bvh e = BuildBvh(std::move(empty), o);
        CHECK(e.nodes.empty());
        CHECK(SahCost(e) == 0.0);
        for (int n = 1; n <= 2; ++n) {
            std::vector<float> v;
            for (int t = 0; t < n; ++t) v.insert(v.end(), {float(t), 0, 0, 1, 0, 0, 0, 1, 0});
            const Built b = BuildFrom(ViewOf(v), o);
            CHECK(b.bvh.stats.references == uint32_t(n));
            RequireSound(b);
        }
        std::vector<float> nan(9 * 100, NAN);
        const Built b = BuildFrom(ViewOf(nan), o);
        CHECK(b.bvh.nodes.empty());
        CHECK(b.input.excludedInactive == 100);
    }
}

TEST_CASE("I3: an instance of a BLAS without active primitives is a point at its translation", "[bvh][I3]") {
    VkAccelerationStructureInstanceKHR inst[3] = {};
    const float m[12] = {2, 0, 0, 10, 0, 3, 0, 20, 0, 0, 4, 30};
    for (auto& i : inst) std::memcpy(&i.transform, m, sizeof m);
    inst[0].accelerationStructureReference = 1;  // empty BLAS
    inst[1].accelerationStructureReference = 2;  // BLAS with a box
    inst[2].accelerationStructureReference = 3;  // unknown (I5): excluded
    InstanceGeometryView v;
    v.data = inst;
    v.dataBytes = sizeof inst;
    v.range.primitiveCount = 3;
    BuildInput in;
    AppendInstances(v, [](uint64_t ref, void*) {
        BlasSummary s;
        s.known = ref != 3;
        s.activePrimitives = ref == 2 ? 5 : 0;
        for (int a = 0; a < 3; ++a) { s.lo[a] = -1; s.hi[a] = 1; }
        return s;
    }, nullptr, 0, &in);
    REQUIRE(in.refs.size() == 2);
    CHECK(in.degenerateInstances == 1);
    CHECK(in.excludedInvalid == 1);
    for (int a = 0; a < 3; ++a) {
        CHECK(in.refs[0].lo[a] == m[4 * a + 3]);
        CHECK(in.refs[0].hi[a] == m[4 * a + 3]);
    }
    CHECK(in.refs[1].lo[0] <= 8.0f);
    CHECK(in.refs[1].hi[0] >= 12.0f);
    CHECK(in.refs[1].hi[0] == 12.0f);  // exact results are not widened
}

// Large enough that the expansion releases the pages of the references it has read (page_release.h):
// a leaf box or id read from a released page would be zero and fail the containment / id checks.
TEST_CASE("builds that release their references while expanding stay sound", "[bvh][memory]") {
    const scenes::Scene s = scenes::Uniform(150000, 5);
    for (BuildMode mode : {BuildMode::BinnedSah, BuildMode::Lbvh}) {
        for (uint32_t threads : {1u, 2u}) {
            BuildOptions o;
            o.mode = mode;
            o.threads = threads;
            INFO("mode " << int(mode) << " threads " << threads);
            const Built b = BuildFrom(scenes::View(s), o);
            REQUIRE(b.input.refs.size() * sizeof(PrimRef) > (size_t(4) << 20));  // past the release threshold
            RequireSound(b);
        }
    }
}

// Large enough (>= 4 chunks of 64K references) that the root's box and bins are computed by ParallelFor
// chunks that idle threads help with: the result must not depend on who ran which chunk.
TEST_CASE("chunked parallel passes give the same tree at 1, 2 and 3 threads", "[bvh][determinism]") {
    const scenes::Scene s = scenes::Uniform(300000, 17);
    BuildOptions o;
    o.threads = 1;
    const Built a = BuildFrom(scenes::View(s), o);
    RequireSound(a);
    for (uint32_t threads : {2u, 3u}) {
        o.threads = threads;
        const Built b = BuildFrom(scenes::View(s), o);
        INFO("threads " << threads);
        REQUIRE(a.bvh.nodes.size() == b.bvh.nodes.size());
        CHECK(std::memcmp(a.bvh.nodes.data(), b.bvh.nodes.data(), a.bvh.nodes.size() * sizeof(BvhNode)) == 0);
        CHECK(a.bvh.primIds == b.bvh.primIds);
    }
}
