// ClassifyDetail::kActivity (issue 27, item 3): what an update's rules compare, with the per-triangle loop
// skipped when every triangle is readable and no vertex the triangles can read holds a NaN. It must give the very
// record and counts of the full classification: hand cases with their expected values written out, then random
// views against the full loop (ClassifyDetail::kFull, itself pinned by the oracle tests).
#include <catch2/catch_test_macros.hpp>

#include <cstring>
#include <random>
#include <vector>

#include "asval/builder/classify.h"
#include "asval/builder/vertex_format.h"

using namespace asval::builder;

namespace {

constexpr uint32_t kQuietNaN = 0x7FC00000u;

void Put(std::vector<uint8_t>& bytes, size_t at, uint32_t word) { std::memcpy(bytes.data() + at, &word, 4); }
uint32_t FloatBits(float f) { uint32_t b; std::memcpy(&b, &f, 4); return b; }

// A grid of `quads` x 1 quads (two triangles each), float32 XYZ vertices `stride` bytes apart (the bytes between
// them 0), 32-bit indices.
struct Strip {
    std::vector<uint8_t> vertices;
    std::vector<uint32_t> indices;
    uint64_t stride;
    TriangleGeometryView View() const {
        TriangleGeometryView v;
        v.vertexData = vertices.data();
        v.vertexDataBytes = vertices.size();
        v.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
        v.vertexStride = stride;
        v.maxVertex = uint32_t(vertices.size() / stride - 1);
        v.indexType = VK_INDEX_TYPE_UINT32;
        v.indexData = indices.data();
        v.indexDataBytes = indices.size() * 4;
        v.range.primitiveCount = uint32_t(indices.size() / 3);
        return v;
    }
};

Strip MakeStrip(uint32_t quads, uint64_t stride) {
    Strip s;
    s.stride = stride;
    const uint32_t columns = quads + 1;
    s.vertices.assign(2 * columns * stride, 0);
    for (uint32_t row = 0; row < 2; ++row)
        for (uint32_t c = 0; c < columns; ++c) {
            const size_t at = (row * columns + c) * stride;
            Put(s.vertices, at, FloatBits(float(c)));
            Put(s.vertices, at + 4, FloatBits(float(row)));
            Put(s.vertices, at + 8, FloatBits(0.5f));
        }
    for (uint32_t q = 0; q < quads; ++q) {
        const uint32_t a = q, b = q + 1, c = columns + q, d = columns + q + 1;
        s.indices.insert(s.indices.end(), {a, b, c, b, d, c});
    }
    return s;
}

struct Both {
    ClassifyResult full, activity;
    ActivityRecord fullRecord, activityRecord;
};

Both Classify(const TriangleGeometryView& v) {
    Both b;
    b.full = ClassifyTriangles(v, &b.fullRecord, nullptr, ClassifyDetail::kFull);
    b.activity = ClassifyTriangles(v, &b.activityRecord, nullptr, ClassifyDetail::kActivity);
    return b;
}

// Everything kActivity promises equals the full classification's.
void RequireSameActivity(const Both& b) {
    CHECK(b.activity.status == b.full.status);
    CHECK(b.activity.primitiveCount == b.full.primitiveCount);
    CHECK(b.activity.active == b.full.active);
    CHECK(b.activity.inactive == b.full.inactive);
    CHECK(b.activity.undefinedNaN == b.full.undefinedNaN);
    CHECK(b.activity.unreadable == b.full.unreadable);
    CHECK(b.activity.firstUndefined == b.full.firstUndefined);
    CHECK(b.activity.firstUnreadable == b.full.firstUnreadable);
    CHECK(b.activity.transformHasNaN == b.full.transformHasNaN);
    CHECK(b.activity.transformUnreadable == b.full.transformUnreadable);
    CHECK(b.activity.indexHashPartial == b.full.indexHashPartial);
    CHECK(b.activityRecord.primitiveCount == b.fullRecord.primitiveCount);
    CHECK(b.activityRecord.activeCount == b.fullRecord.activeCount);
    CHECK(b.activityRecord.activeBits == b.fullRecord.activeBits);
    CHECK(b.activityRecord.hasIndexHash == b.fullRecord.hasIndexHash);
    CHECK(b.activityRecord.indexHash.lo == b.fullRecord.indexHash.lo);
    CHECK(b.activityRecord.indexHash.hi == b.fullRecord.indexHash.hi);
}

}  // namespace

TEST_CASE("activity only: every triangle finite and readable, all active, the bits set past the first word",
          "[classify][activity]") {
    const Strip s = MakeStrip(50, 12);  // 100 triangles: one whole 64-bit word and 36 bits of the next
    const Both b = Classify(s.View());
    CHECK(b.activity.active == 100);
    CHECK(b.activity.inactive == 0);
    CHECK(b.activity.undefinedNaN == 0);
    CHECK(b.activity.unreadable == 0);
    REQUIRE(b.activityRecord.activeBits.size() == 2);
    CHECK(b.activityRecord.activeBits[0] == ~uint64_t{0});
    CHECK(b.activityRecord.activeBits[1] == (uint64_t{1} << 36) - 1);
    CHECK(b.activityRecord.hasIndexHash);
    CHECK(b.activity.degenerate == 0);  // not counted at this detail
    RequireSameActivity(b);
}

TEST_CASE("activity only: a NaN anywhere a triangle reads is found, X inactive, Y or Z undefined input",
          "[classify][activity]") {
    Strip s = MakeStrip(10, 12);  // vertices 0..10 on row 0, 11..21 on row 1; triangle 2q reads q, q+1, 11+q
    SECTION("X of vertex 4: triangles 6 (3, 4, 14), 7 (4, 15, 14) and 8 (4, 5, 15) inactive") {
        Put(s.vertices, 4 * 12, kQuietNaN);
        const Both b = Classify(s.View());
        CHECK(b.activity.inactive == 3);
        CHECK(b.activityRecord.activeBits[0] == (uint64_t{1} << 20) - 1 - (uint64_t{7} << 6));
        RequireSameActivity(b);
    }
    SECTION("Y of vertex 16: triangles 9, 10 and 11 undefined input, still active") {
        Put(s.vertices, 16 * 12 + 4, kQuietNaN);
        const Both b = Classify(s.View());
        CHECK(b.activity.active == 20);
        CHECK(b.activity.undefinedNaN == 3);
        CHECK(b.activity.firstUndefined == 9);
        RequireSameActivity(b);
    }
    SECTION("Z of the last vertex (21): triangle 19 (10, 21, 20)") {
        Put(s.vertices, 21 * 12 + 8, kQuietNaN);
        const Both b = Classify(s.View());
        CHECK(b.activity.undefinedNaN == 1);
        CHECK(b.activity.firstUndefined == 19);
        RequireSameActivity(b);
    }
}

TEST_CASE("activity only: a NaN the triangles never read changes nothing", "[classify][activity]") {
    SECTION("in the padding between vertices 16 bytes apart") {
        Strip s = MakeStrip(10, 16);
        for (size_t v = 0; v < s.vertices.size() / 16; ++v) Put(s.vertices, v * 16 + 12, kQuietNaN);
        const Both b = Classify(s.View());
        CHECK(b.activity.active == 20);
        CHECK(b.activity.undefinedNaN == 0);
        RequireSameActivity(b);
    }
    SECTION("in a vertex between the smallest and the largest index that no triangle names") {
        Strip s = MakeStrip(10, 12);
        // Triangles 0..9 only (quads 0..4): they read vertices 0..5 and 11..16; vertex 8 lies between, unread.
        s.indices.resize(30);
        Put(s.vertices, 8 * 12, kQuietNaN);
        const Both b = Classify(s.View());
        CHECK(b.activity.active == 10);
        RequireSameActivity(b);
    }
}

TEST_CASE("activity only: unreadable triangles and missing indices are counted as the full classification does",
          "[classify][activity]") {
    Strip s = MakeStrip(10, 12);
    SECTION("an index past the vertices provided") {
        s.indices[7] = 1000;  // triangle 2
        const Both b = Classify(s.View());
        CHECK(b.activity.unreadable == 1);
        CHECK(b.activity.firstUnreadable == 2);
        RequireSameActivity(b);
    }
    SECTION("fewer index bytes than the triangles need: the hash is partial") {
        TriangleGeometryView v = s.View();
        v.indexDataBytes -= 4;
        const Both b = Classify(v);
        CHECK(b.activity.indexHashPartial);
        CHECK(b.activity.unreadable == 1);
        RequireSameActivity(b);
    }
}

TEST_CASE("activity only: random views give the full classification's record and counts", "[classify][activity]") {
    std::mt19937 rng(27);
    const VkFormat formats[] = {VK_FORMAT_R32G32B32_SFLOAT, VK_FORMAT_R32G32_SFLOAT, VK_FORMAT_R16G16B16A16_SFLOAT,
                                VK_FORMAT_R16G16_SFLOAT, VK_FORMAT_R16G16B16A16_SNORM, VK_FORMAT_R8G8B8A8_UNORM};
    const VkIndexType indexTypes[] = {VK_INDEX_TYPE_NONE_KHR, VK_INDEX_TYPE_UINT8_EXT, VK_INDEX_TYPE_UINT16,
                                      VK_INDEX_TYPE_UINT32};
    for (int round = 0; round < 3000; ++round) {
        const VkFormat format = formats[rng() % 6];
        const VertexFormatInfo* info = FindVertexFormat(format);
        REQUIRE(info);
        const VkIndexType indexType = indexTypes[rng() % 4];
        const uint32_t indexBytes = uint32_t(IndexTypeBytes(indexType));
        const uint32_t triangles = 1 + rng() % 300;
        const uint32_t vertices = 3 + rng() % 200;
        const uint64_t stride = info->vertexBytes + info->componentBytes * (rng() % 4) * (rng() % 3 == 0 ? 8 : 1);
        const uint32_t firstVertex = rng() % 3 == 0 ? rng() % 8 : 0;
        std::vector<uint8_t> vertexBytes(vertices * stride + 16);
        for (auto& byte : vertexBytes) byte = uint8_t(rng() % 7 == 0 ? 0x7F : rng() % 0x70);  // few NaNs
        if (rng() % 2 == 0) {  // most rounds: no NaN at all, the fast path's case
            for (size_t i = 1; i < vertexBytes.size(); i += 2) vertexBytes[i] &= 0x3F;
        }
        std::vector<uint8_t> indexData(size_t(3) * triangles * std::max(indexBytes, 1u));
        const uint32_t span = rng() % 4 == 0 ? vertices + 20 : vertices;  // sometimes past the vertices
        for (uint32_t i = 0; i < 3 * triangles; ++i) {
            uint32_t value = rng() % span;
            if (indexBytes == 1) value &= 0xFF;
            std::memcpy(indexData.data() + size_t(i) * indexBytes, &value, indexBytes);
        }
        TriangleGeometryView v;
        v.vertexData = vertexBytes.data();
        v.vertexDataBytes = vertices * stride - (rng() % 3 == 0 ? rng() % stride : 0);
        v.vertexFormat = format;
        v.vertexStride = stride;
        v.maxVertex = vertices - 1;
        v.indexType = indexType;
        if (indexBytes != 0) {
            v.indexData = indexData.data();
            v.indexDataBytes = indexData.size() - (rng() % 5 == 0 ? rng() % 7 : 0);
            v.range.firstVertex = firstVertex;
        }
        v.range.primitiveCount = indexBytes != 0 ? triangles : std::min(triangles, vertices / 3);
        INFO("round " << round << " format " << format << " index bytes " << indexBytes << " stride " << stride);
        RequireSameActivity(Classify(v));
    }
}
