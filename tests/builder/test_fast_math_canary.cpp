// Fast-math canary. docs/builder.md decides that "X is NaN" is tested on the source bits, before any
// arithmetic, so activity holds in a -ffast-math build. This executable links only asval_builder_fastmath
// (the classification sources compiled a second time WITH -ffast-math); the oracle and this file are built
// normally. Activity (state bit, record bit, counts), the undefined-input flag (also a bit test) and the
// same-index flag are asserted against the oracle. Degeneracy (and an AABB's min > max) uses IEEE
// comparisons and is NOT expected to hold under fast-math: differences are counted and printed, never
// asserted. Runs are repeated with FTZ/DAZ set, as crtfastmath.o does in a fast-math program.
#include <catch2/catch_test_macros.hpp>

#include <xmmintrin.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "asval/builder/vertex_format.h"
#include "fast_math_probe.h"
#include "test_support.h"

using namespace asval::builder;
using testsupport::Rng;

namespace {

// What a fast-math program's startup code (crtfastmath.o) sets: flush-to-zero and denormals-are-zero.
class FlushDenormals {
public:
    FlushDenormals() : saved_(_mm_getcsr()) { _mm_setcsr(saved_ | 0x8040u); }
    ~FlushDenormals() { _mm_setcsr(saved_); }
    FlushDenormals(const FlushDenormals&) = delete;
    FlushDenormals& operator=(const FlushDenormals&) = delete;

private:
    unsigned saved_;
};

struct Tally {
    uint64_t primitives = 0, inactive = 0, undefined = 0;
    uint64_t activityMismatches = 0;  // asserted 0: state bit, record bit or totals differ from the oracle
    uint64_t flagMismatches = 0;      // asserted 0: undefined-input or same-index flag differs
    uint64_t degenerateDiffers = 0;   // reported only (IEEE == under fast-math) ...
    uint64_t degenerateDiffersDefined = 0;  // ... of which on primitives without any NaN
    std::string first, firstDegenerate;
    void Note(std::string& where, uint64_t& counter, const std::string& what) {
        if (counter++ == 0) where = what;
    }
};

void RequireActivity(const Tally& t, const char* what) {
    INFO(what << ": " << t.first);
    CHECK(t.activityMismatches == 0);
    CHECK(t.flagMismatches == 0);
    std::printf("fast-math canary, %s: %llu primitives, %llu inactive, %llu undefined-input; degeneracy "
                "differs from the oracle on %llu (%llu without NaN)%s%s\n",
                what, (unsigned long long)t.primitives, (unsigned long long)t.inactive,
                (unsigned long long)t.undefined, (unsigned long long)t.degenerateDiffers,
                (unsigned long long)t.degenerateDiffersDefined,
                t.firstDegenerate.empty() ? "" : ", first: ", t.firstDegenerate.c_str());
}

// The record must hold exactly ceil(n/64) words with bit i = primitive i active, and the right counts.
void CheckRecordShape(const ActivityRecord& record, uint32_t n, uint32_t active, Tally& t) {
    if (record.primitiveCount != n || record.activeCount != active || record.activeBits.size() != (size_t(n) + 63) / 64)
        t.Note(t.first, t.activityMismatches, "record counts / size");
}

// Classifies `view` with the fast-math copy and compares with the oracle, triangle by triangle.
void CheckTriangles(const TriangleGeometryView& view, Tally& t) {
    const uint32_t n = view.range.primitiveCount;
    std::vector<uint8_t> states(n);
    ActivityRecord record;
    const ClassifyResult r = ClassifyTriangles(view, &record, states.data());
    const oracle::TriangleInput in{view.vertexFormat, static_cast<const uint8_t*>(view.vertexData), view.vertexStride,
                                   view.maxVertex, view.indexType, static_cast<const uint8_t*>(view.indexData),
                                   view.range.primitiveOffset, view.range.firstVertex};
    uint32_t active = 0, undefined = 0;
    for (uint32_t i = 0; i < n; ++i) {
        const oracle::Triangle o = oracle::ClassifyTriangle(in, i);
        const uint8_t s = states[i];
        active += o.active;
        const auto at = [i] { return "triangle " + std::to_string(i); };
        if (bool(s & kStateActive) != o.active || record.IsActive(i) != o.active) {
            t.Note(t.first, t.activityMismatches, at() + ": active");
            continue;
        }
        if (!o.active) continue;
        undefined += o.undefined;
        if (bool(s & kStateUndefined) != o.undefined || bool(s & kStateSameIndex) != o.sameIndex)
            t.Note(t.first, t.flagMismatches, at() + ": undefined / same-index flag");
        if (bool(s & kStateDegenerate) != o.degenerate) {
            t.degenerateDiffersDefined += !o.undefined;
            t.Note(t.firstDegenerate, t.degenerateDiffers, at() + (o.undefined ? " (undefined input)" : ""));
        }
    }
    if (r.active != active || r.inactive != n - active || r.undefinedNaN != undefined || r.primitiveCount != n)
        t.Note(t.first, t.activityMismatches, "result totals");
    CheckRecordShape(record, n, active, t);
    t.primitives += n;
    t.inactive += n - active;
    t.undefined += undefined;
}

// ---- Component codes.

uint32_t AnyFloatNaN(Rng& rng) { return uint32_t(rng.Next() & 1) << 31 | 0x7F800000u | (1u + rng.Below(0x7FFFFFu)); }
uint32_t AnyHalfNaN(Rng& rng) { return uint32_t(rng.Next() & 1) << 15 | 0x7C00u | (1u + rng.Below(0x3FFu)); }

// Float32 codes that are not NaN, weighted toward the values where a sloppy test goes wrong.
uint32_t OrdinaryFloat(Rng& rng) {
    const uint32_t sign = uint32_t(rng.Next() & 1) << 31;
    switch (rng.Below(6)) {
        case 0: return sign;                                   // +-0
        case 1: return sign | 0x7F800000u;                     // +-inf
        case 2: return sign | (1u + rng.Below(0x7FFFFEu));     // subnormal
        case 3: return sign | 0x7F7FFFFFu;                     // FLT_MAX
        default: {
            const uint32_t b = uint32_t(rng.Next());
            return (b & 0x7F800000u) == 0x7F800000u ? b & 0xBFFFFFFFu : b;  // any finite value
        }
    }
}

// Half codes drawn so that equalities are frequent: the varied code itself, specials, random codes.
uint32_t HalfPick(Rng& rng, uint32_t code) {
    static const uint32_t kSpecial[] = {0x0000u, 0x8000u, 0x3C00u, 0x7C00u, 0xFC00u, 0x7E00u, 0x7C01u, 0x0001u, 0x8001u};
    switch (rng.Below(4)) {
        case 0: return code;
        case 1: return kSpecial[rng.Below(9)];
        default: return rng.Below(0x10000u);
    }
}

// Cheap filler for the millions of components around the enumerated NaN patterns: a fixed table of
// ordinary float32 codes (and, for Y/Z, a few NaNs), walked with a random odd step.
class Filler {
public:
    Filler(Rng& rng, bool withNaN) : rng_(rng) {
        for (uint32_t& c : table_) c = withNaN && rng.Below(16) == 0 ? AnyFloatNaN(rng) : OrdinaryFloat(rng);
    }
    uint32_t Next() {
        if ((++count_ & 1023) == 0) step_ = 1 + 2 * rng_.Below(kSize / 2);
        return table_[at_ = (at_ + step_) % kSize];
    }

private:
    static constexpr uint32_t kSize = 4093;  // prime: every odd step visits the whole table
    Rng& rng_;
    uint32_t table_[kSize];
    uint32_t at_ = 0, step_ = 1, count_ = 0;
};

struct Geometry {
    std::vector<uint8_t> vertices;
    std::vector<uint32_t> reversed;  // indices that read the triangles in reverse order
    uint64_t stride = 0;
    uint32_t triangles = 0;
};

// Non-indexed (one vertex of primitiveOffset, firstVertex 1) and indexed (uint32, reversed order, a NaN in
// the transform) views of the same triangles.
void CheckNonIndexed(const VertexFormatInfo& f, Geometry& g, Tally& t) {
    std::vector<uint8_t> shifted(g.vertices.size() + 2 * g.stride);
    std::memcpy(shifted.data() + 2 * g.stride, g.vertices.data(), g.vertices.size());
    TriangleGeometryView flat;
    flat.vertexData = shifted.data();
    flat.vertexDataBytes = shifted.size();
    flat.vertexFormat = f.format;
    flat.vertexStride = g.stride;
    flat.maxVertex = 3 * g.triangles;
    flat.range = {g.triangles, uint32_t(g.stride), 1, 0};
    CheckTriangles(flat, t);
}

void CheckIndexed(const VertexFormatInfo& f, Geometry& g, Tally& t) {
    g.reversed.resize(size_t(g.triangles) * 3);
    for (uint32_t i = 0; i < g.triangles; ++i)
        for (uint32_t k = 0; k < 3; ++k) g.reversed[3 * i + k] = 3 * (g.triangles - 1 - i) + k;
    float transform[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    const uint32_t nan = 0xFFC00001u;
    std::memcpy(&transform[7], &nan, 4);
    TriangleGeometryView indexed;
    indexed.vertexData = g.vertices.data();
    indexed.vertexDataBytes = g.vertices.size();
    indexed.vertexFormat = f.format;
    indexed.vertexStride = g.stride;
    indexed.maxVertex = 3 * g.triangles - 1;
    indexed.indexType = VK_INDEX_TYPE_UINT32;
    indexed.indexData = g.reversed.data();
    indexed.indexDataBytes = g.reversed.size() * 4;
    indexed.transformData = transform;
    indexed.transformDataBytes = sizeof transform;
    indexed.range = {g.triangles, 0, 0, 0};
    CheckTriangles(indexed, t);
}

void CheckBothModes(const VertexFormatInfo& f, Geometry& g, Tally& t) {
    CheckNonIndexed(f, g, t);
    CheckIndexed(f, g, t);
}

// Every chunk in one of the two modes (the oracle is the cost), alternating.
void CheckOneMode(const VertexFormatInfo& f, Geometry& g, Tally& t, int chunk) {
    if (chunk & 1) CheckIndexed(f, g, t);
    else CheckNonIndexed(f, g, t);
}

// Every half code in every X/Y/Z slot of every vertex; the other components are picked so that equality
// is frequent, and in every other triangle vertex 1 starts as a copy of vertex 0.
Geometry ExhaustiveHalf(const VertexFormatInfo& f, uint64_t seed) {
    Geometry g;
    const int xyz = f.componentCount >= 3 ? 3 : 2;
    const int slots = 3 * xyz;
    g.stride = f.vertexBytes + 2;
    g.triangles = 0x10000u * uint32_t(slots);
    g.vertices.assign(size_t(g.triangles) * 3 * g.stride, 0xFF);  // W (4-component formats): NaN bits, ignored
    Rng rng(seed);
    uint32_t i = 0;
    for (uint32_t code = 0; code < 0x10000u; ++code)
        for (int slot = 0; slot < slots; ++slot, ++i) {
            uint8_t* tri = g.vertices.data() + size_t(i) * 3 * g.stride;
            for (int v = 0; v < 3; ++v)
                for (int c = 0; c < xyz; ++c) testsupport::WriteComponent(f.format, tri + v * g.stride, c, HalfPick(rng, code));
            if (i & 1) std::memcpy(tri + g.stride, tri, f.vertexBytes);
            testsupport::WriteComponent(f.format, tri + (slot / xyz) * g.stride, slot % xyz, code);
        }
    return g;
}

// The float32 NaN patterns, numbered 0 .. 2*(2^23-1)-1: both signs, every non-zero fraction.
constexpr uint32_t kNaNPerSign = 0x7FFFFFu;
constexpr uint32_t kFloatNaNs = 2 * kNaNPerSign;
uint32_t FloatNaNPattern(uint32_t p) {
    return (p >= kNaNPerSign ? 0x80000000u : 0u) | 0x7F800000u | (p % kNaNPerSign + 1);
}

// Triangles [.., count) for NaN patterns [first, first + count): pattern i is the X of vertex i % 3 of
// triangle i (so it alone makes the triangle inactive); the other components are ordinary values,
// with an occasional NaN in Y or Z.
Geometry FloatNaNsInX(const VertexFormatInfo& f, uint32_t first, uint32_t count, Rng& rng) {
    Geometry g;
    const int xyz = f.componentCount >= 3 ? 3 : 2;
    g.stride = f.vertexBytes;
    g.triangles = count;
    g.vertices.assign(size_t(count) * 3 * g.stride, 0xFF);
    Filler x(rng, false), yz(rng, true);
    for (uint32_t i = 0; i < count; ++i) {
        uint8_t* tri = g.vertices.data() + size_t(i) * 3 * g.stride;
        for (int v = 0; v < 3; ++v)
            for (int c = 0; c < xyz; ++c) {
                const uint32_t code = v == int(i % 3) && c == 0 ? FloatNaNPattern(first + i) : c == 0 ? x.Next() : yz.Next();
                std::memcpy(tri + v * g.stride + 4 * c, &code, 4);
            }
    }
    return g;
}

// Patterns [first, first + 3*(xyz-1)*count) in the Y/Z slots, X ordinary: every triangle stays active.
Geometry FloatNaNsInYz(const VertexFormatInfo& f, uint32_t first, uint32_t count, Rng& rng) {
    Geometry g;
    const int xyz = f.componentCount >= 3 ? 3 : 2;
    g.stride = f.vertexBytes;
    g.triangles = count;
    g.vertices.assign(size_t(count) * 3 * g.stride, 0xFF);
    Filler x(rng, false);
    uint32_t p = first;
    for (uint32_t i = 0; i < count; ++i) {
        uint8_t* tri = g.vertices.data() + size_t(i) * 3 * g.stride;
        for (int v = 0; v < 3; ++v)
            for (int c = 0; c < xyz; ++c) {
                const uint32_t code = c == 0 ? x.Next() : FloatNaNPattern(p++ % kFloatNaNs);
                std::memcpy(tri + v * g.stride + 4 * c, &code, 4);
            }
    }
    return g;
}

const VertexFormatInfo& Format(VkFormat f) { return *FindVertexFormat(f); }

}  // namespace

TEST_CASE("the classifier copy is a fast-math build that folds value NaN tests", "[fastmath]") {
    REQUIRE(fastmathprobe::BuiltWithFastMath());
    // With these flags `x != x` is compiled to false: a value-based NaN test would see no NaN at all.
    volatile float nan = std::numeric_limits<float>::quiet_NaN();
    CHECK_FALSE(fastmathprobe::ValueNaNTest(nan));
}

TEST_CASE("every half encoding in every slot matches the oracle's activity", "[fastmath][exhaustive]") {
    for (VkFormat fmt : {VK_FORMAT_R16G16_SFLOAT, VK_FORMAT_R16G16B16_SFLOAT, VK_FORMAT_R16G16B16A16_SFLOAT}) {
        const VertexFormatInfo& f = Format(fmt);
        INFO("format " << int(fmt));
        Geometry g = ExhaustiveHalf(f, 77 + uint64_t(fmt));
        Tally t;
        CheckBothModes(f, g, t);
        RequireActivity(t, ("half, format " + std::to_string(int(fmt))).c_str());
        CHECK(t.inactive > t.primitives / 100);   // the generator reaches every class
        CHECK(t.undefined > t.primitives / 100);
        Tally flushed;
        {
            FlushDenormals ftzDaz;
            CheckNonIndexed(f, g, flushed);
        }
        RequireActivity(flushed, ("half with FTZ/DAZ, format " + std::to_string(int(fmt))).c_str());
    }
}

namespace {

const VkFormat kFloatFormats[] = {VK_FORMAT_R32G32B32_SFLOAT, VK_FORMAT_R32G32_SFLOAT, VK_FORMAT_R32G32B32A32_SFLOAT};
constexpr uint32_t kChunk = 1u << 20;

// Patterns [first, end) in X, one per triangle, in chunks that rotate format and mode.
void FloatNaNsInXRange(uint32_t first, uint32_t end, uint64_t seed) {
    Rng rng(seed);
    Tally x;
    int chunk = 0;
    for (uint32_t p = first; p < end; p += kChunk, ++chunk) {
        const VertexFormatInfo& f = Format(kFloatFormats[chunk % 3]);
        Geometry g = FloatNaNsInX(f, p, std::min(kChunk, end - p), rng);
        CheckOneMode(f, g, x, chunk);
    }
    CHECK(x.primitives == end - first);  // every pattern once
    CHECK(x.inactive == x.primitives);
    RequireActivity(x, ("float32 NaN patterns " + std::to_string(first) + ".." + std::to_string(end - 1) + " in X").c_str());
}

}  // namespace

TEST_CASE("every positive float32 NaN pattern in X makes the triangle inactive", "[fastmath][exhaustive]") {
    FloatNaNsInXRange(0, kNaNPerSign, 2024);
}

TEST_CASE("every negative float32 NaN pattern in X makes the triangle inactive", "[fastmath][exhaustive]") {
    FloatNaNsInXRange(kNaNPerSign, kFloatNaNs, 2025);
}

TEST_CASE("every float32 NaN pattern in Y or Z keeps the triangle active", "[fastmath][exhaustive]") {
    Rng rng(2026);
    Tally yz;
    int chunk = 0;
    for (uint32_t first = 0; first < kFloatNaNs; ++chunk) {
        const VertexFormatInfo& f = Format(kFloatFormats[chunk % 3]);
        const uint32_t perTriangle = 3 * uint32_t((f.componentCount >= 3 ? 3 : 2) - 1);
        const uint32_t count = std::min(kChunk / 4, (kFloatNaNs - first + perTriangle - 1) / perTriangle);
        Geometry g = FloatNaNsInYz(f, first, count, rng);
        CheckOneMode(f, g, yz, chunk);
        first += count * perTriangle;
    }
    CHECK(yz.inactive == 0);
    CHECK(yz.undefined == yz.primitives);
    RequireActivity(yz, "float32 NaN patterns in Y/Z");
}

TEST_CASE("AABBs with every float32 NaN pattern as minX and in the other slots", "[fastmath][exhaustive]") {
    constexpr uint32_t kChunk = 1u << 20;
    Rng rng(5);
    Tally t;
    uint64_t invalidDiffers = 0;
    std::vector<uint8_t> states;
    ActivityRecord record;
    // Pass 0: pattern in minX (inactive). Pass 1: five patterns per AABB in the other slots (active).
    // Pass 2: one chunk of ordinary boxes (an occasional NaN outside minX), for the degeneracy figures.
    for (int pass = 0; pass < 3; ++pass) {
        const uint32_t perAabb = pass == 0 ? 1 : 5;
        for (uint32_t first = 0; first < (pass < 2 ? kFloatNaNs : 1);) {
            const uint32_t count = pass == 2 ? kChunk : std::min(kChunk, (kFloatNaNs - first + perAabb - 1) / perAabb);
            const uint64_t stride = 24 + 8 * rng.Below(2);
            std::vector<uint8_t> data(stride * count + 16);
            Filler ordinary(rng, false), others(rng, true);
            uint32_t p = first;
            for (uint32_t i = 0; i < count; ++i) {
                uint8_t* a = data.data() + 16 + stride * i;
                const uint32_t equalMask = ordinary.Next() & 7;  // max == min on these axes
                for (int c = 0; c < 6; ++c) {
                    uint32_t bits = c == 0 ? ordinary.Next() : others.Next();
                    if (c >= 3 && (equalMask >> (c - 3) & 1)) std::memcpy(&bits, a + 4 * (c - 3), 4);
                    if (pass == 0 ? c == 0 : pass == 1 && c > 0) bits = FloatNaNPattern(p++ % kFloatNaNs);
                    std::memcpy(a + 4 * c, &bits, 4);
                }
            }
            first = pass == 2 ? 1 : first + count * perAabb;
            AabbGeometryView view;
            view.data = data.data();
            view.dataBytes = data.size();
            view.stride = stride;
            view.range = {count, 16, 0, 0};
            states.assign(count, 0xEE);
            const ClassifyResult r = ClassifyAabbs(view, &record, states.data());
            uint32_t active = 0, undefined = 0;
            for (uint32_t i = 0; i < count; ++i) {
                // The oracle's IEEE decoder on (minX, minY, minZ) and (maxX, maxY, maxZ).
                oracle::Vertex lo, hi;
                oracle::DecodeVertex(VK_FORMAT_R32G32B32_SFLOAT, data.data() + 16 + stride * i, &lo);
                const bool isActive = !lo.c[0].nan;
                active += isActive;
                if (bool(states[i] & kStateActive) != isActive || record.IsActive(i) != isActive) {
                    t.Note(t.first, t.activityMismatches, "AABB " + std::to_string(i) + ": active");
                    continue;
                }
                if (!isActive) continue;
                oracle::DecodeVertex(VK_FORMAT_R32G32B32_SFLOAT, data.data() + 16 + stride * i + 12, &hi);
                const bool undef = lo.c[1].nan || lo.c[2].nan || hi.c[0].nan || hi.c[1].nan || hi.c[2].nan;
                undefined += undef;
                if (bool(states[i] & kStateUndefined) != undef)
                    t.Note(t.first, t.flagMismatches, "AABB " + std::to_string(i) + ": undefined flag");
                bool degenerate = true, invalid = false;
                for (int a = 0; a < 3; ++a) {
                    const bool nan = lo.c[a].nan || hi.c[a].nan;
                    degenerate &= !nan && lo.c[a].value == hi.c[a].value;
                    invalid |= !nan && lo.c[a].value > hi.c[a].value;
                }
                if (bool(states[i] & kStateDegenerate) != degenerate) {
                    ++t.degenerateDiffers;
                    t.degenerateDiffersDefined += !undef;
                }
                invalidDiffers += bool(states[i] & kStateInvalidAabb) != invalid;
            }
            if (r.active != active || r.inactive != count - active || r.undefinedNaN != undefined)
                t.Note(t.first, t.activityMismatches, "AABB totals");
            CheckRecordShape(record, count, active, t);
            t.primitives += count;
            t.inactive += count - active;
            t.undefined += undefined;
        }
    }
    CHECK(t.inactive == kFloatNaNs);
    RequireActivity(t, "AABBs");
    std::printf("fast-math canary, AABBs: min > max (invalid) differs from the oracle on %llu\n",
                (unsigned long long)invalidDiffers);
}

TEST_CASE("an instance is active iff its reference is not 0", "[fastmath]") {
    Rng rng(8);
    for (int trial = 0; trial < 50; ++trial) {
        const uint32_t n = 1 + rng.Below(3000);
        std::vector<uint8_t> instances(size_t(n) * 64);
        std::vector<const void*> pointers(n);
        std::vector<bool> expected(n);
        for (uint32_t i = 0; i < n; ++i) {
            for (auto k = 0; k < 64; ++k) instances[size_t(i) * 64 + size_t(k)] = uint8_t(rng.Next());
            const uint64_t reference = rng.Below(3) == 0 ? 0 : rng.Next() | 1;  // NaN-looking bits elsewhere
            std::memcpy(&instances[size_t(i) * 64 + 56], &reference, 8);
            expected[i] = reference != 0;
            pointers[i] = &instances[size_t(i) * 64];
        }
        InstanceGeometryView view;
        view.arrayOfPointers = trial & 1;
        view.data = view.arrayOfPointers ? static_cast<const void*>(pointers.data()) : instances.data();
        view.dataBytes = view.arrayOfPointers ? n * sizeof(void*) : instances.size();
        view.range.primitiveCount = n;
        ActivityRecord record;
        const ClassifyResult r = ClassifyInstances(view, &record, nullptr);
        uint32_t active = 0, mismatches = 0;
        for (uint32_t i = 0; i < n; ++i) {
            active += expected[i];
            mismatches += record.IsActive(i) != expected[i];
        }
        CHECK(mismatches == 0);
        CHECK(r.active == active);
        CHECK(record.activeCount == active);
        CHECK(record.primitiveCount == n);
    }
}

TEST_CASE("random half and float32 triangles of every index type match the oracle's activity",
          "[fastmath][random]") {
    const VkFormat formats[] = {VK_FORMAT_R32G32_SFLOAT, VK_FORMAT_R32G32B32_SFLOAT, VK_FORMAT_R32G32B32A32_SFLOAT,
                                VK_FORMAT_R16G16_SFLOAT, VK_FORMAT_R16G16B16_SFLOAT, VK_FORMAT_R16G16B16A16_SFLOAT};
    const VkIndexType indexTypes[] = {VK_INDEX_TYPE_NONE_KHR, VK_INDEX_TYPE_UINT16, VK_INDEX_TYPE_UINT32,
                                      VK_INDEX_TYPE_UINT8_EXT};
    const uint64_t batches = 48 * testsupport::TestScale();
    const uint32_t perBatch = 20000;
    Rng rng(31);
    Tally t;
    for (uint64_t b = 0; b < batches; ++b) {
        const VertexFormatInfo& f = Format(formats[b % 6]);
        const VkIndexType it = indexTypes[(b / 6) % 4];
        const int indexBytes = IndexTypeBytes(it);
        const bool half = f.kind == ComponentKind::Float16;
        const int xyz = f.componentCount >= 3 ? 3 : 2;
        const uint64_t stride = f.vertexBytes + 2 * rng.Below(3);
        const uint32_t firstVertex = rng.Below(4);
        const uint32_t vertexCount = indexBytes == 0 ? firstVertex + 3 * perBatch + 1
                                   : indexBytes == 1 ? 256 : 300 + rng.Below(indexBytes == 2 ? 60000 : 200000);
        uint32_t pool[8];
        for (uint32_t& p : pool) p = half ? rng.Below(0x10000u) : uint32_t(rng.Next());
        std::vector<uint8_t> vertices(size_t(vertexCount) * stride + 16);
        for (uint32_t v = 0; v < vertexCount; ++v)
            for (int c = 0; c < xyz; ++c) {
                uint32_t code;
                switch (rng.Below(8)) {
                    case 0: code = half ? AnyHalfNaN(rng) : AnyFloatNaN(rng); break;
                    case 1: case 2: code = pool[rng.Below(8)]; break;
                    case 3: code = half ? (rng.Below(2) ? 0x8000u : 0u) | rng.Below(0x400u) : OrdinaryFloat(rng); break;
                    default: code = half ? rng.Below(0x10000u) : uint32_t(rng.Next()); break;
                }
                testsupport::WriteComponent(f.format, vertices.data() + v * stride, c, code);
            }
        TriangleGeometryView view;
        view.vertexData = vertices.data();
        view.vertexDataBytes = vertices.size();
        view.vertexFormat = f.format;
        view.vertexStride = stride;
        view.indexType = it;
        std::vector<uint8_t> indices;
        if (indexBytes != 0) {
            const uint32_t offset = uint32_t(indexBytes) * rng.Below(4);
            indices.resize(offset + size_t(perBatch) * 3 * size_t(indexBytes));
            const uint32_t span = vertexCount - firstVertex;
            for (size_t i = 0; i < size_t(perBatch) * 3; ++i) {
                const uint32_t idx = rng.Below(8) == 0 ? uint32_t(i / 3) % span : rng.Below(span);
                for (int k = 0; k < indexBytes; ++k) indices[offset + i * size_t(indexBytes) + size_t(k)] = uint8_t(idx >> (8 * k));
            }
            view.indexData = indices.data();
            view.indexDataBytes = indices.size();
            view.range = {perBatch, offset, firstVertex, 0};
        } else {
            view.range = {perBatch, uint32_t(stride), firstVertex, 0};
        }
        view.maxVertex = vertexCount - 1;
        float transform[12];
        for (float& m : transform) {
            const uint32_t bits = rng.Below(4) == 0 ? AnyFloatNaN(rng) : OrdinaryFloat(rng);
            std::memcpy(&m, &bits, 4);
        }
        if (rng.Below(2)) {
            view.transformData = transform;
            view.transformDataBytes = sizeof transform;
        }
        if (b % 5 == 4) {
            FlushDenormals ftzDaz;
            CheckTriangles(view, t);
        } else {
            CheckTriangles(view, t);
        }
    }
    CHECK(t.inactive > t.primitives / 10);
    CHECK(t.undefined > t.primitives / 100);
    RequireActivity(t, "random triangles");
}
