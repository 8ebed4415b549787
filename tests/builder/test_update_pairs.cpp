// U1 at scale: random build -> update pairs through ClassifyTriangles / ClassifyAabbs + CompareActivity.
// Each pair draws a format, an index type, a transform (or none) and a geometry, then an update of one kind:
//   flip        - random primitives change activity (active -> inactive and inactive -> active): the diff
//                 must name exactly the changed primitives (count, direction, the first ones, ascending);
//   degeneracy  - vertices move, X keeps its NaN-ness: degeneracy changes, activity not: must be silent;
//   index       - index values change: the index hash must differ (VUID 03768); activity may change too;
//   nothing     - same geometry: silent.
// The update is always laid out afresh (new buffers, another primitiveOffset, other junk in the padding
// and in ignored W components), so the records must not depend on the layout. The expected diff comes
// from the independent oracle (oracle.cpp) run on both views, never from the builder.
// CI runs 4 000 triangle + 1 000 AABB pairs; ASVAL_TEST_SCALE=25 gives the >= 10^5 pairs of the stress table.
#include <catch2/catch_test_macros.hpp>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "asval/builder/vertex_format.h"
#include "test_support.h"

using namespace asval::builder;
using testsupport::Rng;

namespace {

enum class Kind { Flip, Degeneracy, IndexValues, Nothing, Count };
const char* const kKindNames[] = {"flip", "degeneracy", "index", "nothing"};

// ---- Component codes of a format (raw codes as testsupport::WriteComponent takes them).

bool IsNaNCode(const VertexFormatInfo& f, uint32_t code) {
    if (f.kind == ComponentKind::Float32) return (code & 0x7FFFFFFFu) > 0x7F800000u;
    if (f.kind == ComponentKind::Float16) return (code & 0x7FFFu) > 0x7C00u;
    return false;
}

uint32_t NaNCode(const VertexFormatInfo& f, Rng& rng) {
    if (f.kind == ComponentKind::Float32) return uint32_t(rng.Next() & 1) << 31 | 0x7F800000u | (1u + rng.Below(0x7FFFFFu));
    return uint32_t(rng.Next() & 1) << 15 | 0x7C00u | (1u + rng.Below(0x3FFu));
}

uint32_t RandomCode(const VertexFormatInfo& f, Rng& rng) {
    const unsigned bits = f.componentBits;
    return bits >= 32 ? uint32_t(rng.Next()) : uint32_t(rng.Next()) & ((1u << bits) - 1);
}

// A code that is not NaN: from the geometry's small pool (so equal components, hence degeneracy, are
// frequent), a signed zero (+0 == -0), or anything.
uint32_t OrdinaryCode(const VertexFormatInfo& f, Rng& rng, const std::vector<uint32_t>& pool) {
    uint32_t c;
    switch (rng.Below(4)) {
        case 0: case 1: c = pool[rng.Below(uint32_t(pool.size()))]; break;
        case 2: c = f.kind == ComponentKind::Float32 ? (rng.Below(2) ? 0x80000000u : 0u)
                  : f.kind == ComponentKind::Float16 ? (rng.Below(2) ? 0x8000u : 0u) : RandomCode(f, rng); break;
        default: c = RandomCode(f, rng); break;
    }
    while (IsNaNCode(f, c)) c = RandomCode(f, rng);
    return c;
}

// ---- A triangle geometry as codes and indices, independent of where it lies in memory.

struct Source {
    const VertexFormatInfo* f = nullptr;
    int xyz = 3;
    VkIndexType indexType = VK_INDEX_TYPE_NONE_KHR;
    int indexBytes = 0;
    uint32_t n = 0, vertexCount = 0, firstVertex = 0;
    uint64_t stride = 0;
    std::vector<uint32_t> codes;    // vertexCount x 3 (non-indexed: vertex j of the range)
    std::vector<uint32_t> indices;  // 3n (indexed only)
    std::vector<uint32_t> pool;
    bool hasTransform = false;

    uint32_t& Code(uint32_t vertex, int c) { return codes[size_t(vertex) * 3 + size_t(c)]; }
    uint32_t VertexOf(uint32_t t, int k) const { return indexBytes ? indices[3 * size_t(t) + size_t(k)] : 3 * t + uint32_t(k); }
    bool ActiveByCodes(uint32_t t) {
        for (int k = 0; k < 3; ++k)
            if (IsNaNCode(*f, Code(VertexOf(t, k), 0))) return false;
        return true;
    }
};

uint32_t NewComponent(Source& s, Rng& rng, int c) {
    const bool nan = s.f->hasNaN && rng.Below(c == 0 ? 6 : 20) == 0;
    return nan ? NaNCode(*s.f, rng) : OrdinaryCode(*s.f, rng, s.pool);
}

Source RandomSource(const VertexFormatInfo& f, VkIndexType indexType, Rng& rng) {
    Source s;
    s.f = &f;
    s.xyz = f.componentCount >= 3 ? 3 : 2;
    s.indexType = indexType;
    s.indexBytes = IndexTypeBytes(indexType);
    s.n = rng.Below(20) == 0 ? 1 + rng.Below(5000) : 1 + rng.Below(200);  // > 4096: several hash chunks
    s.firstVertex = rng.Below(3);
    s.stride = f.vertexBytes + f.componentBytes * rng.Below(3);
    const uint32_t indexRange = s.indexBytes == 1 ? 256 : s.indexBytes == 2 ? 65536 : UINT32_MAX;
    s.vertexCount = s.indexBytes == 0 ? 3 * s.n : std::min<uint32_t>(indexRange, 3 + rng.Below(2 * s.n + 3));
    for (int i = 0; i < 6; ++i) s.pool.push_back(OrdinaryCode(f, rng, {RandomCode(f, rng)}));
    s.codes.assign(size_t(s.vertexCount) * 3, 0);
    for (uint32_t v = 0; v < s.vertexCount; ++v)
        for (int c = 0; c < s.xyz; ++c) s.Code(v, c) = NewComponent(s, rng, c);
    if (s.indexBytes) {
        s.indices.resize(size_t(s.n) * 3);
        for (auto& i : s.indices) i = rng.Below(s.vertexCount);
    }
    s.hasTransform = rng.Below(2);
    return s;
}

// Fresh buffers for `s`: a random primitiveOffset, random junk in the stride padding, W and around.
struct Laid {
    std::vector<uint8_t> vertices, indices;
    float transform[16];
    TriangleGeometryView view;
};

void Lay(const Source& s, Rng& rng, Laid* out) {
    Laid& l = *out;
    TriangleGeometryView& v = l.view;
    v = TriangleGeometryView{};
    v.vertexFormat = s.f->format;
    v.vertexStride = s.stride;
    v.indexType = s.indexType;
    const uint32_t primitiveOffset = s.indexBytes ? uint32_t(s.indexBytes) * rng.Below(5) : 4 * rng.Below(4);
    // Non-indexed: vertex j of the range lies at primitiveOffset + stride * (firstVertex + j).
    const uint64_t base = s.indexBytes ? 0 : primitiveOffset + s.stride * s.firstVertex;
    const uint32_t slots = s.indexBytes ? s.vertexCount + s.firstVertex : s.vertexCount;
    l.vertices.resize(base + size_t(slots) * s.stride + rng.Below(8));
    for (auto& b : l.vertices) b = uint8_t(rng.Next());
    for (uint32_t j = 0; j < s.vertexCount; ++j) {
        // Indexed: index value i reads vertex i + firstVertex.
        uint8_t* p = l.vertices.data() + base + size_t(j + (s.indexBytes ? s.firstVertex : 0)) * s.stride;
        for (int c = 0; c < s.xyz; ++c) testsupport::WriteComponent(s.f->format, p, c, s.codes[size_t(j) * 3 + size_t(c)]);
    }
    v.vertexData = l.vertices.data();
    v.vertexDataBytes = l.vertices.size();
    if (s.indexBytes) {
        l.indices.resize(primitiveOffset + s.indices.size() * size_t(s.indexBytes) + rng.Below(4));
        for (auto& b : l.indices) b = uint8_t(rng.Next());
        for (size_t i = 0; i < s.indices.size(); ++i)
            for (int k = 0; k < s.indexBytes; ++k)
                l.indices[primitiveOffset + i * size_t(s.indexBytes) + size_t(k)] = uint8_t(s.indices[i] >> (8 * k));
        v.indexData = l.indices.data();
        v.indexDataBytes = l.indices.size();
        v.maxVertex = s.vertexCount - 1 + s.firstVertex;
    } else {
        v.maxVertex = s.firstVertex + s.vertexCount - 1;
    }
    v.range = {s.n, primitiveOffset, s.firstVertex, 0};
    if (s.hasTransform) {  // values (NaN included) may change on update; only its presence must not
        for (float& m : l.transform) {
            const uint32_t bits = rng.Below(8) == 0 ? 0x7FC00000u : uint32_t(rng.Next());
            std::memcpy(&m, &bits, 4);
        }
        v.transformData = l.transform;
        v.transformDataBytes = sizeof l.transform;
        v.range.transformOffset = 16 * rng.Below(2);
    }
}

// ---- Mutations of a Source (the update's geometry).

void FlipActivity(Source& s, Rng& rng) {
    const uint32_t flips = rng.Below(4) == 0 ? 1 + rng.Below(std::max<uint32_t>(1, s.n / 2)) : 1 + rng.Below(std::min<uint32_t>(s.n, 6));
    for (uint32_t k = 0; k < flips; ++k) {
        const uint32_t t = rng.Below(s.n);
        if (s.ActiveByCodes(t)) {
            s.Code(s.VertexOf(t, int(rng.Below(3))), 0) = NaNCode(*s.f, rng);
        } else {
            for (int i = 0; i < 3; ++i) {
                uint32_t& x = s.Code(s.VertexOf(t, i), 0);
                if (IsNaNCode(*s.f, x)) x = OrdinaryCode(*s.f, rng, s.pool);
            }
        }
    }
}

// Moves vertices without changing whether any X is NaN: copy components between two vertices of one
// triangle (makes it degenerate) or redraw one component (often makes a degenerate one proper again).
void MoveVertices(Source& s, Rng& rng) {
    const uint32_t edits = 1 + rng.Below(4);
    for (uint32_t e = 0; e < edits; ++e) {
        const uint32_t t = rng.Below(s.n);
        const uint32_t a = s.VertexOf(t, int(rng.Below(3))), b = s.VertexOf(t, int(rng.Below(3)));
        if (rng.Below(2)) {
            for (int c = 0; c < s.xyz; ++c)
                if (c > 0 || IsNaNCode(*s.f, s.Code(a, 0)) == IsNaNCode(*s.f, s.Code(b, 0))) s.Code(b, c) = s.Code(a, c);
        } else {
            const int c = int(rng.Below(uint32_t(s.xyz)));
            uint32_t& code = s.Code(b, c);
            if (c > 0) code = NewComponent(s, rng, c);
            else code = IsNaNCode(*s.f, code) ? NaNCode(*s.f, rng) : OrdinaryCode(*s.f, rng, s.pool);
        }
    }
}

// Redraws 1-3 index values; a later edit may restore an earlier one, so the last one always leaves the
// array different from the original (the test compares the arrays, not the edits, anyway).
void ChangeIndices(Source& s, Rng& rng) {
    const std::vector<uint32_t> original = s.indices;
    const uint32_t edits = 1 + rng.Below(3);
    for (uint32_t e = 0; e < edits || s.indices == original; ++e) {
        uint32_t& i = s.indices[rng.Below(uint32_t(s.indices.size()))];
        const uint32_t old = i;
        while (i == old) i = rng.Below(s.vertexCount);
    }
}

// ---- Oracle side.

struct OracleState {
    std::vector<bool> active, degenerate;
    uint32_t activeCount = 0;
};

OracleState OracleOf(const TriangleGeometryView& v) {
    const oracle::TriangleInput in{v.vertexFormat, static_cast<const uint8_t*>(v.vertexData), v.vertexStride,
                                   v.maxVertex, v.indexType, static_cast<const uint8_t*>(v.indexData),
                                   v.range.primitiveOffset, v.range.firstVertex};
    OracleState o;
    o.active.resize(v.range.primitiveCount);
    o.degenerate.resize(v.range.primitiveCount);
    for (uint32_t t = 0; t < v.range.primitiveCount; ++t) {
        const oracle::Triangle r = oracle::ClassifyTriangle(in, t);
        o.active[t] = r.active;
        o.degenerate[t] = r.active && r.degenerate;
        o.activeCount += r.active;
    }
    return o;
}

struct Outcome {
    uint64_t pairs = 0, falsePositives = 0, misses = 0, inexact = 0, recordErrors = 0;
    uint64_t pairsWithActivityChange = 0, pairsWithDegeneracyChange = 0, becameActive = 0, becameInactive = 0;
    uint64_t hashChanges = 0;
    std::string first;
    void Fail(uint64_t& counter, const std::string& what) {
        if (falsePositives + misses + inexact + recordErrors == 0) first = what;
        ++counter;
    }
};

// Compares CompareActivity's answer with the oracle's diff of `before` and `after`.
void Judge(const std::vector<bool>& before, const std::vector<bool>& after, bool indicesChanged,
           const ActivityRecord& rb, const ActivityRecord& ra, Rng& rng, Outcome& o, const std::string& pair) {
    std::vector<ActivityChange> expected;
    uint64_t up = 0;
    for (size_t i = 0; i < before.size(); ++i)
        if (before[i] != after[i]) {
            expected.push_back({uint32_t(i), bool(after[i])});
            up += after[i];
        }
    ActivityChange got[8];
    const size_t maxReport = 1 + rng.Below(8);
    const ActivityDiff d = CompareActivity(rb, ra, got, maxReport);
    if (expected.empty() && d.changedCount != 0) o.Fail(o.falsePositives, pair + ": activity change reported, none happened");
    if (!indicesChanged && d.indexHashDiffers) o.Fail(o.falsePositives, pair + ": index hash differs, indices unchanged");
    if (!expected.empty() && d.changedCount == 0) o.Fail(o.misses, pair + ": activity change not reported");
    if (indicesChanged && !d.indexHashDiffers) o.Fail(o.misses, pair + ": index change not reported");
    bool exact = d.changedCount == expected.size() && d.becameActive == up &&
                 d.becameInactive == expected.size() - up && !d.primitiveCountDiffers &&
                 d.reported == std::min(maxReport, expected.size());
    for (size_t k = 0; exact && k < d.reported; ++k)
        exact = got[k].primitive == expected[k].primitive && got[k].becameActive == expected[k].becameActive;
    if (!exact) o.Fail(o.inexact, pair + ": count or first changed primitives differ");
    o.pairsWithActivityChange += !expected.empty();
    o.becameActive += up;
    o.becameInactive += expected.size() - up;
    o.hashChanges += d.indexHashDiffers;
}

const VkFormat kNaNFormats[] = {VK_FORMAT_R32G32_SFLOAT, VK_FORMAT_R32G32B32_SFLOAT, VK_FORMAT_R32G32B32A32_SFLOAT,
                                VK_FORMAT_R16G16_SFLOAT, VK_FORMAT_R16G16B16_SFLOAT, VK_FORMAT_R16G16B16A16_SFLOAT};
const VkIndexType kIndexTypes[] = {VK_INDEX_TYPE_NONE_KHR, VK_INDEX_TYPE_UINT8_EXT, VK_INDEX_TYPE_UINT16,
                                   VK_INDEX_TYPE_UINT32};

void Report(const Outcome (&byKind)[4], const char* what) {
    for (int k = 0; k < 4; ++k) {
        const Outcome& o = byKind[k];
        if (o.pairs == 0) continue;  // AABBs have no index kind
        std::printf("U1 %s, %-10s: %llu pairs, %llu with activity changes (+%llu / -%llu primitives), %llu with "
                    "degeneracy changes, %llu index-hash changes; false positives %llu, misses %llu, inexact %llu\n",
                    what, kKindNames[k], (unsigned long long)o.pairs, (unsigned long long)o.pairsWithActivityChange,
                    (unsigned long long)o.becameActive, (unsigned long long)o.becameInactive,
                    (unsigned long long)o.pairsWithDegeneracyChange, (unsigned long long)o.hashChanges,
                    (unsigned long long)o.falsePositives, (unsigned long long)o.misses, (unsigned long long)o.inexact);
    }
}

void RequireClean(const Outcome& o) {
    INFO(o.first);
    CHECK(o.falsePositives == 0);
    CHECK(o.misses == 0);
    CHECK(o.inexact == 0);
    CHECK(o.recordErrors == 0);
}

}  // namespace

TEST_CASE("U1: random triangle build -> update pairs are reported exactly with 0 false positives and 0 misses",
          "[record][U1][random]") {
    const uint64_t pairs = 4000 * testsupport::TestScale();
    Rng rng(0xB1D);
    Outcome byKind[4];
    Laid built, updated;
    ActivityRecord before, after;  // reused across pairs, as the layer would
    for (uint64_t p = 0; p < pairs; ++p) {
        const Kind kind = Kind(rng.Below(uint32_t(Kind::Count)));
        // Activity can only flip in formats with NaN; index values only change in indexed geometry.
        const VertexFormatInfo& f = kind == Kind::Flip ? *FindVertexFormat(kNaNFormats[rng.Below(6)])
                                                       : VertexFormatsBegin()[rng.Below(uint32_t(VertexFormatsEnd() - VertexFormatsBegin()))];
        const VkIndexType it = kIndexTypes[kind == Kind::IndexValues ? 1 + rng.Below(3) : rng.Below(4)];
        Source s = RandomSource(f, it, rng);
        const std::vector<uint32_t> builtIndices = s.indices;
        Lay(s, rng, &built);
        switch (kind) {
            case Kind::Flip: FlipActivity(s, rng); break;
            case Kind::Degeneracy: MoveVertices(s, rng); break;
            case Kind::IndexValues: ChangeIndices(s, rng); break;
            default: break;
        }
        Lay(s, rng, &updated);
        const ClassifyResult rb = ClassifyTriangles(built.view, &before, nullptr);
        const ClassifyResult ra = ClassifyTriangles(updated.view, &after, nullptr);
        const OracleState ob = OracleOf(built.view), oa = OracleOf(updated.view);
        Outcome& o = byKind[int(kind)];
        const std::string pair = "pair " + std::to_string(p) + " (" + kKindNames[int(kind)] + ", format " +
                                 std::to_string(int(f.format)) + ", index bytes " + std::to_string(s.indexBytes) + ")";
        ++o.pairs;
        if (rb.status != ClassifyStatus::Ok || rb.unreadable || ra.unreadable || rb.overMaxVertex || ra.overMaxVertex ||
            before.activeCount != ob.activeCount || after.activeCount != oa.activeCount ||
            before.hasIndexHash != (s.indexBytes != 0) || after.hasIndexHash != (s.indexBytes != 0))
            o.Fail(o.recordErrors, pair + ": record / classification");
        Judge(ob.active, oa.active, s.indices != builtIndices, before, after, rng, o, pair);
        o.pairsWithDegeneracyChange += ob.degenerate != oa.degenerate;
        if (kind == Kind::Degeneracy && ob.active != oa.active) o.Fail(o.recordErrors, pair + ": generator changed activity");
    }
    Report(byKind, "triangles");
    for (const Outcome& o : byKind) RequireClean(o);
    // The generator reaches what it claims (a test that cannot fail is no test).
    const Outcome &flip = byKind[0], &degen = byKind[1], &index = byKind[2], &nothing = byKind[3];
    CHECK(flip.pairsWithActivityChange >= flip.pairs * 95 / 100);
    CHECK(flip.becameActive > flip.pairs / 4);
    CHECK(flip.becameInactive > flip.pairs / 4);
    CHECK(degen.pairsWithDegeneracyChange >= degen.pairs / 3);
    CHECK(degen.pairsWithActivityChange == 0);
    CHECK(index.hashChanges == index.pairs);
    CHECK(nothing.pairsWithActivityChange == 0);
    CHECK(nothing.hashChanges == 0);
}

TEST_CASE("U1: random AABB build -> update pairs are reported exactly", "[record][U1][random]") {
    const uint64_t pairs = 1000 * testsupport::TestScale();
    Rng rng(0xAAB);
    Outcome byKind[4];
    ActivityRecord before, after;
    auto minXNaN = [](const std::vector<uint32_t>& a, uint32_t i) { return (a[6 * i] & 0x7FFFFFFFu) > 0x7F800000u; };
    for (uint64_t p = 0; p < pairs; ++p) {
        Kind kind = Kind(rng.Below(uint32_t(Kind::Count)));
        if (kind == Kind::IndexValues) kind = Kind::Nothing;  // AABBs have no indices
        const uint32_t n = rng.Below(20) == 0 ? 1 + rng.Below(3000) : 1 + rng.Below(200);
        const std::vector<uint32_t> pool = {0u, 0x80000000u, 0x3F800000u, uint32_t(rng.Next()) & 0xBFFFFFFFu};
        auto draw = [&](int c) {
            if (rng.Below(c == 0 ? 6 : 24) == 0) return 0x7F800000u | (1u + rng.Below(0x7FFFFFu)) | uint32_t(rng.Next() & 1) << 31;
            return pool[rng.Below(4)];
        };
        std::vector<uint32_t> a(size_t(n) * 6);  // minX minY minZ maxX maxY maxZ
        for (uint32_t i = 0; i < n; ++i)
            for (int c = 0; c < 6; ++c) a[6 * i + size_t(c)] = c >= 3 && rng.Below(2) ? a[6 * i + size_t(c) - 3] : draw(c);
        std::vector<uint32_t> b = a;
        const uint32_t edits = 1 + rng.Below(std::min<uint32_t>(n, 6));
        for (uint32_t e = 0; kind != Kind::Nothing && e < edits; ++e) {
            const uint32_t i = rng.Below(n);
            if (kind == Kind::Flip) {
                b[6 * i] = minXNaN(b, i) ? pool[rng.Below(4)] : 0xFFC00000u | rng.Below(0x3FFFFFu);
            } else {  // degeneracy / other components: min == max toggles, NaN outside minX allowed
                const int c = 1 + int(rng.Below(5));
                b[6 * i + size_t(c)] = c >= 3 && rng.Below(2) ? b[6 * i + size_t(c) - 3] : draw(c);
                if (rng.Below(2) && !minXNaN(b, i)) b[6 * i + 3] = b[6 * i];
            }
        }
        std::vector<bool> activeBefore(n), activeAfter(n);
        ActivityRecord* records[2] = {&before, &after};
        bool degeneracyChanged = false;
        for (int side = 0; side < 2; ++side) {
            const std::vector<uint32_t>& src = side ? b : a;
            const uint64_t stride = 24 + 8 * rng.Below(2);
            const uint32_t offset = 8 * rng.Below(3);
            std::vector<uint8_t> data(offset + stride * n);
            for (auto& x : data) x = uint8_t(rng.Next());
            for (uint32_t i = 0; i < n; ++i) std::memcpy(data.data() + offset + stride * i, &src[6 * i], 24);
            AabbGeometryView view;
            view.data = data.data();
            view.dataBytes = data.size();
            view.stride = stride;
            view.range = {n, offset, 0, 0};
            std::vector<uint8_t> states(n);
            ClassifyAabbs(view, records[side], states.data());
            for (uint32_t i = 0; i < n; ++i) {
                oracle::Vertex lo;  // the oracle's IEEE decoder on (minX, minY, minZ)
                oracle::DecodeVertex(VK_FORMAT_R32G32B32_SFLOAT, data.data() + offset + stride * i, &lo);
                (side ? activeAfter : activeBefore)[i] = !lo.c[0].nan;
            }
        }
        auto pointBits = [](const std::vector<uint32_t>& x, uint32_t i) {  // min == max bit for bit
            return x[6 * i] == x[6 * i + 3] && x[6 * i + 1] == x[6 * i + 4] && x[6 * i + 2] == x[6 * i + 5];
        };
        for (uint32_t i = 0; i < n; ++i) degeneracyChanged |= pointBits(a, i) != pointBits(b, i);  // reach proxy
        Outcome& o = byKind[int(kind)];
        ++o.pairs;
        const std::string pair = "AABB pair " + std::to_string(p) + " (" + kKindNames[int(kind)] + ")";
        if (before.hasIndexHash || after.hasIndexHash) o.Fail(o.recordErrors, pair + ": index hash on AABBs");
        Judge(activeBefore, activeAfter, false, before, after, rng, o, pair);
        o.pairsWithDegeneracyChange += degeneracyChanged;
    }
    Report(byKind, "AABBs");
    for (const Outcome& o : byKind) RequireClean(o);
    CHECK(byKind[0].pairsWithActivityChange >= byKind[0].pairs * 95 / 100);
    CHECK(byKind[0].becameActive > 0);
    CHECK(byKind[0].becameInactive > 0);
    CHECK(byKind[1].pairsWithDegeneracyChange >= byKind[1].pairs / 3);
    CHECK(byKind[1].pairsWithActivityChange == 0);
    CHECK(byKind[3].pairsWithActivityChange == 0);
}
