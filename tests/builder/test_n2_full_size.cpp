// N2 at full size: 2^24 - 1 primitives, lavapipe's maxPrimitiveCount (16 777 215). Classification with the
// activity record (0.125 B/prim kept), a default-options BVH build and the tree checks, plus AABB and
// instance classification at the same count. Too big for CI (2.0 GB peak RSS, ~20 s wall): hidden tag.
//   build/tests/builder/asval_builder_tests "[.long]"
//   /usr/bin/time -v build/tests/builder/asval_builder_tests "[N2][.long]"     (peak: "Maximum resident")
// CI keeps the small N2 cases (test_bvh.cpp: 0, 1, 2 primitives, all inactive).
#include <catch2/catch_test_macros.hpp>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <string>
#include <vector>

#include "asval/builder/bvh.h"
#include "asval/builder/bvh_triangles.h"
#include "bvh_checks.h"
#include "test_support.h"

using namespace asval::builder;

namespace {

constexpr uint32_t kMaxPrimitiveCount = (1u << 24) - 1;

// Peak resident set so far (VmHWM), in MiB; 0 where /proc is not available.
double PeakMiB() {
    std::ifstream status("/proc/self/status");
    std::string line;
    while (std::getline(status, line))
        if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
    return 0;
}

// CPU seconds since the last call (process time: the machine is shared).
double Lap() {
    static std::clock_t last = std::clock();
    const std::clock_t now = std::clock();
    const double s = double(now - last) / CLOCKS_PER_SEC;
    last = now;
    return s;
}

void Phase(const char* what) { std::printf("N2 full size: %-34s %7.2f s CPU, peak RSS %7.0f MiB\n", what, Lap(), PeakMiB()); }

// A 4097 x 2049 vertex height field, two triangles per cell: 2^24 triangles, of which the first 2^24 - 1
// are used. Some vertices have X = NaN (their triangles are inactive), every 1000th triangle repeats an
// index (same-index, degenerate) and rows of height 0 with equal Y make flat, non-degenerate triangles.
struct Grid {
    static constexpr uint32_t kW = 4097, kH = 2049;
    std::vector<float> vertices;
    std::vector<uint32_t> indices;
    Grid() {
        vertices.resize(size_t(kW) * kH * 3);
        for (uint32_t j = 0; j < kH; ++j)
            for (uint32_t i = 0; i < kW; ++i) {
                float* v = &vertices[(size_t(j) * kW + i) * 3];
                v[0] = (i * 31u + j * 17u) % 997u == 0 ? std::nanf("") : float(i);
                v[1] = float((i * 7u + j * 13u) % 29u) * 0.25f;
                v[2] = float(j);
            }
        indices.resize(size_t(kMaxPrimitiveCount) * 3);
        size_t t = 0;
        for (uint32_t j = 0; j + 1 < kH && t < kMaxPrimitiveCount; ++j)
            for (uint32_t i = 0; i + 1 < kW && t < kMaxPrimitiveCount; ++i) {
                const uint32_t a = j * kW + i, b = a + 1, c = a + kW, d = c + 1;
                const uint32_t tri[2][3] = {{a, b, d}, {a, d, c}};
                for (int k = 0; k < 2 && t < kMaxPrimitiveCount; ++k, ++t) {
                    std::memcpy(&indices[3 * t], tri[k], sizeof tri[k]);
                    if (t % 1000 == 999) indices[3 * t + 2] = indices[3 * t];
                }
            }
    }
    TriangleGeometryView View() const {
        TriangleGeometryView v;
        v.vertexData = vertices.data();
        v.vertexDataBytes = vertices.size() * sizeof(float);
        v.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
        v.vertexStride = 12;
        v.maxVertex = kW * kH - 1;
        v.indexType = VK_INDEX_TYPE_UINT32;
        v.indexData = indices.data();
        v.indexDataBytes = indices.size() * sizeof(uint32_t);
        v.range.primitiveCount = kMaxPrimitiveCount;
        return v;
    }
};

void CheckRecordMemory(const ActivityRecord& record) {
    // ceil(n/64) words of 8 bytes: 0.125 B per primitive (2 MiB for 2^24 - 1).
    CHECK(record.activeBits.size() == (size_t(kMaxPrimitiveCount) + 63) / 64);
    CHECK(record.HeapBytes() <= (size_t(kMaxPrimitiveCount) + 63) / 64 * 8);
    std::printf("N2 full size: activity record %zu bytes = %.4f B/prim (+ %zu B struct)\n", record.HeapBytes(),
                double(record.HeapBytes()) / kMaxPrimitiveCount, sizeof record);
}

}  // namespace

TEST_CASE("N2 full size: 2^24-1 AABBs and instances classify with exact counts and a 0.125 B/prim record",
          "[.long][N2]") {
    Lap();
    {
        // AABBs: minX NaN on every 7th, point boxes on every 5th.
        std::vector<float> aabbs(size_t(kMaxPrimitiveCount) * 6);
        uint32_t inactive = 0, degenerate = 0;
        for (uint32_t i = 0; i < kMaxPrimitiveCount; ++i) {
            float* a = &aabbs[size_t(i) * 6];
            const float x = float(i % 4096), y = float(i / 4096);
            const float e = i % 5 == 0 ? 0.0f : 0.5f;
            const float box[6] = {i % 7 == 3 ? std::nanf("") : x, y, 0, x + e, y + e, e};
            std::memcpy(a, box, sizeof box);
            inactive += i % 7 == 3;
            degenerate += i % 7 != 3 && i % 5 == 0;
        }
        AabbGeometryView view;
        view.data = aabbs.data();
        view.dataBytes = aabbs.size() * sizeof(float);
        view.stride = 24;
        view.range.primitiveCount = kMaxPrimitiveCount;
        Phase("AABB input");
        ActivityRecord record;
        const ClassifyResult r = ClassifyAabbs(view, &record, nullptr);
        Phase("AABB classification");
        CHECK(r.inactive == inactive);
        CHECK(r.degenerate == degenerate);
        CHECK(record.activeCount == kMaxPrimitiveCount - inactive);
        CHECK(record.primitiveCount == kMaxPrimitiveCount);
        const uint32_t lastInactive = kMaxPrimitiveCount - 1 - (kMaxPrimitiveCount - 1 - 3) % 7;
        CHECK(!record.IsActive(lastInactive));
        CHECK(record.IsActive(lastInactive + 1));
        CheckRecordMemory(record);
    }
    {
        // Instances through arrayOfPointers (8 B each): every 3rd points at a null-reference instance.
        uint8_t instances[2][64] = {};
        const uint64_t reference = 0x1000;
        std::memcpy(&instances[1][56], &reference, 8);
        std::vector<const void*> pointers(kMaxPrimitiveCount);
        for (uint32_t i = 0; i < kMaxPrimitiveCount; ++i) pointers[i] = instances[i % 3 == 0 ? 0 : 1];
        InstanceGeometryView view;
        view.data = pointers.data();
        view.dataBytes = pointers.size() * sizeof(void*);
        view.arrayOfPointers = true;
        view.range.primitiveCount = kMaxPrimitiveCount;
        ActivityRecord record;
        const ClassifyResult r = ClassifyInstances(view, &record, nullptr);
        Phase("instance classification");
        const uint32_t nullReferences = (kMaxPrimitiveCount + 2) / 3;  // i % 3 == 0
        CHECK(r.inactive == nullReferences);
        CHECK(record.activeCount == kMaxPrimitiveCount - nullReferences);
        CHECK(!record.IsActive(kMaxPrimitiveCount - 1 - (kMaxPrimitiveCount - 1) % 3));
        CHECK(record.IsActive(kMaxPrimitiveCount - 1 - (kMaxPrimitiveCount - 1) % 3 + 1));
        CheckRecordMemory(record);
    }
}

TEST_CASE("N2 full size: 2^24-1 triangles classify exactly and build a sound default BVH", "[.long][N2]") {
    Lap();
    const Grid grid;
    const TriangleGeometryView view = grid.View();
    Phase("grid input (100 + 201 MB)");

    // The oracle's counts, and its activity bit for every triangle.
    const oracle::TriangleInput in{view.vertexFormat, static_cast<const uint8_t*>(view.vertexData), view.vertexStride,
                                   view.maxVertex, view.indexType, static_cast<const uint8_t*>(view.indexData), 0, 0};
    std::vector<bool> oracleActive(kMaxPrimitiveCount);
    uint32_t active = 0, degenerate = 0, sameIndex = 0;
    for (uint32_t t = 0; t < kMaxPrimitiveCount; ++t) {
        const oracle::Triangle o = oracle::ClassifyTriangle(in, t);
        oracleActive[t] = o.active;
        active += o.active;
        degenerate += o.active && o.degenerate;
        sameIndex += o.active && o.sameIndex;
    }
    Phase("oracle");
    REQUIRE(active > kMaxPrimitiveCount / 2);
    REQUIRE(active < kMaxPrimitiveCount);
    REQUIRE(sameIndex > 10000);

    ActivityRecord record;
    const ClassifyResult r = ClassifyTriangles(view, &record, nullptr);
    const double classifySeconds = Lap();
    std::printf("N2 full size: classification %.3f s CPU (%.0f Mtri/s)\n", classifySeconds,
                classifySeconds > 0 ? kMaxPrimitiveCount / classifySeconds / 1e6 : 0.0);
    CHECK(r.status == ClassifyStatus::Ok);
    CHECK(r.primitiveCount == kMaxPrimitiveCount);
    CHECK(r.active == active);
    CHECK(r.inactive == kMaxPrimitiveCount - active);
    CHECK(r.degenerate == degenerate);
    CHECK(r.sameIndex == sameIndex);
    CHECK(r.unreadable == 0);
    CHECK(r.overMaxVertex == 0);
    CHECK(record.primitiveCount == kMaxPrimitiveCount);
    CHECK(record.activeCount == active);
    CHECK(record.hasIndexHash);
    uint32_t bitMismatches = 0;
    for (uint32_t t = 0; t < kMaxPrimitiveCount; ++t) bitMismatches += record.IsActive(t) != oracleActive[t];
    CHECK(bitMismatches == 0);
    CheckRecordMemory(record);
    // The update path at full size: flipping the very last primitive is reported at it.
    {
        ActivityRecord updated = record;
        updated.activeBits.back() ^= uint64_t(1) << ((kMaxPrimitiveCount - 1) % 64);
        ActivityChange first[2];
        const ActivityDiff d = CompareActivity(record, updated, first, 2);
        CHECK(d.changedCount == 1);
        REQUIRE(d.reported == 1);
        CHECK(first[0].primitive == kMaxPrimitiveCount - 1);
    }
    oracleActive = {};
    Phase("record checks");

    BuildInput excluded;
    const Bvh bvh = BuildTriangleBvh(&view, 1, /*allowUpdate=*/true, BuildOptions{}, &excluded);
    Phase("BVH build (default options)");
    std::printf("N2 full size: %zu nodes, %u references, %u leaves, depth %u, largest leaf %u, spatial splits %s\n",
                bvh.nodes.size(), bvh.stats.references, bvh.stats.leaves, bvh.stats.maxDepth, bvh.stats.maxLeafSize,
                bvh.stats.usedSpatialSplits ? "yes" : "no");
    // ALLOW_UPDATE: degenerate triangles stay, same-index ones and inactive ones never enter the tree.
    CHECK(excluded.excludedInactive == kMaxPrimitiveCount - active);
    CHECK(excluded.excludedSameIndex == sameIndex);
    CHECK(excluded.excludedUndefined == 0);
    CHECK(excluded.excludedUnreadable == 0);
    if (!bvh.stats.usedSpatialSplits) CHECK(bvh.stats.references == active - sameIndex);
    CHECK(bvh.stats.maxDepth <= 64);
    CHECK(bvh.stats.maxLeafSize <= 8);
    CHECK(std::isfinite(SahCost(bvh)));
    {
        // The tree against the conservative primitive boxes: every kept id exactly once, inside its leaf.
        BuildInput refs;
        AppendTriangles(view, true, 0, &refs);
        REQUIRE(refs.refs.size() == size_t(active - sameIndex));
        const auto refsById = bvhcheck::RefsById(refs);
        refs = {};
        const bool splits = bvh.stats.usedSpatialSplits;  // pieces are smaller than their triangle's box
        const bvhcheck::Report report =
            bvhcheck::CheckTree(bvh, splits ? std::vector<PrimRef>{} : refsById, 8, !splits);
        INFO(report.first);
        CHECK(report.violations == 0);
    }
    Phase("tree checks");
}
