// The anchors document's classification cases (T1..T11, A1, A2, I1, I2) with their expected behaviour,
// and the decisions on the spec's open questions, each pinned by name.
#include <catch2/catch_test_macros.hpp>

#include <cmath>
#include <cstring>
#include <vector>

#include "asval/builder/classify.h"
#include "asval/builder/vertex_format.h"

using namespace asval::builder;

namespace {

float Bits(uint32_t b) { float f; std::memcpy(&f, &b, 4); return f; }

struct Tri { float v[3][3]; };

struct Classified {
    ClassifyResult result;
    std::vector<uint8_t> states;
    ActivityRecord record;
};

Classified RunF32(const std::vector<Tri>& tris, const float* transform = nullptr) {
    Classified c;
    c.states.resize(tris.size());
    TriangleGeometryView v;
    v.vertexData = tris.data();
    v.vertexDataBytes = tris.size() * sizeof(Tri);
    v.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    v.vertexStride = 12;
    v.maxVertex = uint32_t(tris.size() * 3 - 1);
    v.transformData = transform;
    v.transformDataBytes = transform ? 48 : 0;
    v.range.primitiveCount = uint32_t(tris.size());
    c.result = ClassifyTriangles(v, &c.record, c.states.data());
    return c;
}

const Tri kGood = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}};

}  // namespace

TEST_CASE("T1: any NaN in a vertex X makes the triangle inactive, before any arithmetic", "[classify][T1]") {
    const uint32_t nans[] = {0x7FC00000u, 0x7F800001u, 0xFFC00000u, 0xFF800001u, 0x7FFFFFFFu, 0x7FA5A5A5u};
    std::vector<Tri> tris;
    for (uint32_t n : nans)
        for (int vert = 0; vert < 3; ++vert) {
            Tri t = kGood;
            t.v[vert][0] = Bits(n);
            tris.push_back(t);
        }
    tris.push_back(kGood);
    const float identity[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    for (const float* xf : {static_cast<const float*>(nullptr), identity}) {
        Classified c = RunF32(tris, xf);
        CHECK(c.result.inactive == tris.size() - 1);
        CHECK(c.record.activeCount == 1);
        for (size_t i = 0; i + 1 < tris.size(); ++i) CHECK(c.states[i] == 0);
        CHECK(c.record.IsActive(uint32_t(tris.size() - 1)));
    }
    // Half NaNs: every encoding 0x7C01..0x7FFF and 0xFC01..0xFFFF in X is inactive.
    std::vector<uint16_t> halves;
    uint32_t count = 0;
    for (uint32_t h = 0; h < 0x10000u; ++h) {
        if ((h & 0x7FFFu) <= 0x7C00u) continue;
        const uint16_t tri[3][2] = {{uint16_t(h), 0}, {0x3C00, 0}, {0, 0x3C00}};
        halves.insert(halves.end(), &tri[0][0], &tri[0][0] + 6);
        ++count;
    }
    CHECK(count == 2046);
    TriangleGeometryView v;
    v.vertexData = halves.data();
    v.vertexDataBytes = halves.size() * 2;
    v.vertexFormat = VK_FORMAT_R16G16_SFLOAT;
    v.vertexStride = 4;
    v.maxVertex = 3 * count - 1;
    v.range.primitiveCount = count;
    CHECK(ClassifyTriangles(v, nullptr, nullptr).inactive == count);
}

TEST_CASE("T2/T4/T6/T9: NaN only in Y/Z is active and flagged; inf, huge, zero-area and subnormals are active",
          "[classify][T2][T4][T6][T9]") {
    Tri yNaN = kGood; yNaN.v[1][1] = Bits(0x7FC00000u);
    Tri zNaN = kGood; zNaN.v[2][2] = Bits(0xFF800001u);
    Tri inf = kGood; inf.v[0][0] = INFINITY; inf.v[1][1] = -INFINITY;
    Tri huge = {{{3.4028235e38f, 0, 0}, {-1e30f, 1.844e18f, 0}, {0, 0, -3.4028235e38f}}};
    Tri collinear = {{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}}};          // zero area, not spec-degenerate
    Tri sliver = {{{0, 0, 0}, {1, 1e-30f, 0}, {2, 0, 1e-30f}}};
    Tri subnormal = {{{Bits(1), 0, 0}, {Bits(2), Bits(1), 0}, {0, Bits(3), Bits(1)}}};  // distinct (no FTZ)
    Classified c = RunF32({yNaN, zNaN, inf, huge, collinear, sliver, subnormal});
    CHECK(c.result.active == 7);
    CHECK(c.result.undefinedNaN == 2);
    CHECK(c.result.firstUndefined == 0);
    CHECK((c.states[0] & kStateUndefined));
    CHECK((c.states[1] & kStateUndefined));
    for (int i = 2; i < 7; ++i) CHECK(c.states[size_t(i)] == kStateActive);
}

TEST_CASE("T3: formats without NaN are always active, even for NaN-looking bit patterns", "[classify][T3]") {
    for (const VertexFormatInfo* f = VertexFormatsBegin(); f != VertexFormatsEnd(); ++f) {
        if (f->hasNaN) continue;
        std::vector<uint8_t> data(size_t(f->vertexBytes) * 3 * 2, 0xFF);
        std::memset(data.data() + 3 * f->vertexBytes, 0x7F, 3 * f->vertexBytes);
        data[3 * f->vertexBytes] = 0;  // second triangle: first vertex differs
        TriangleGeometryView v;
        v.vertexData = data.data();
        v.vertexDataBytes = data.size();
        v.vertexFormat = f->format;
        v.vertexStride = f->vertexBytes;
        v.maxVertex = 5;
        v.range.primitiveCount = 2;
        const ClassifyResult r = ClassifyTriangles(v, nullptr, nullptr);
        INFO("format " << int(f->format));
        CHECK(r.active == 2);
        CHECK(r.undefinedNaN == 0);
        CHECK(r.degenerate == 2);  // all-equal vertices (and the second shares Y, Z)
    }
}

TEST_CASE("T5: spec-degenerate triangles are active and degenerate; +0 equals -0", "[classify][T5]") {
    Tri twoSame = {{{1, 2, 3}, {1, 2, 3}, {4, 5, 6}}};
    Tri signedZero = {{{0, 0, 0}, {-0.0f, -0.0f, -0.0f}, {1, 1, 1}}};
    Tri axisLine = {{{1, 2, 0}, {1, 2, 5}, {1, 2, 9}}};  // X and Y shared: a line parallel to Z
    Tri point = {{{7, 7, 7}, {7, 7, 7}, {7, 7, 7}}};
    Tri oneAxis = {{{1, 0, 0}, {1, 1, 0}, {1, 0, 1}}};   // only X shared: a flat but real triangle
    Classified c = RunF32({twoSame, signedZero, axisLine, point, oneAxis});
    CHECK(c.result.active == 5);
    CHECK(c.result.degenerate == 4);
    CHECK(c.states[4] == kStateActive);
}

TEST_CASE("T7: same index twice is discardable, including UINT16 0xFFFF (no primitive restart)", "[classify][T7]") {
    std::vector<float> verts(3 * 0x10000, 0.0f);
    for (size_t i = 0; i < verts.size() / 3; ++i) verts[3 * i] = float(i);  // all distinct X
    const uint16_t idx[] = {0xFFFF, 0xFFFF, 1, 0, 1, 2, 5, 6, 5};
    TriangleGeometryView v;
    v.vertexData = verts.data();
    v.vertexDataBytes = verts.size() * 4;
    v.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    v.vertexStride = 12;
    v.maxVertex = 0xFFFF;
    v.indexType = VK_INDEX_TYPE_UINT16;
    v.indexData = idx;
    v.indexDataBytes = sizeof idx;
    v.range.primitiveCount = 3;
    uint8_t s[3];
    const ClassifyResult r = ClassifyTriangles(v, nullptr, s);
    CHECK(r.active == 3);
    CHECK(r.sameIndex == 2);
    CHECK(s[0] == (kStateActive | kStateDegenerate | kStateSameIndex));
    CHECK((s[1] & kStateSameIndex) == 0);
    CHECK(r.overMaxVertex == 0);
}

TEST_CASE("T8: SNORM codes -2^(b-1) and -2^(b-1)+1 decode to -1 and are equal by value (decision)", "[classify][T8]") {
    // Decision: degeneracy compares decoded values, not bits (docs/builder.md).
    const int16_t snorm16[3][2] = {{-32768, 0}, {-32767, 0}, {0, 100}};  // v0 == v1 by value only
    const int8_t snorm8[3][2] = {{-128, 5}, {-127, 5}, {3, 9}};
    for (int which = 0; which < 2; ++which) {
        TriangleGeometryView v;
        v.vertexData = which ? static_cast<const void*>(snorm8) : static_cast<const void*>(snorm16);
        v.vertexDataBytes = which ? sizeof snorm8 : sizeof snorm16;
        v.vertexFormat = which ? VK_FORMAT_R8G8_SNORM : VK_FORMAT_R16G16_SNORM;
        v.vertexStride = which ? 2 : 4;
        v.maxVertex = 2;
        v.range.primitiveCount = 1;
        uint8_t s = 0;
        ClassifyTriangles(v, nullptr, &s);
        CHECK(s == (kStateActive | kStateDegenerate));
        float a[3], b[3];
        DecodeVertex(*FindVertexFormat(v.vertexFormat), v.vertexData, a);
        DecodeVertex(*FindVertexFormat(v.vertexFormat), static_cast<const uint8_t*>(v.vertexData) + v.vertexStride, b);
        CHECK(a[0] == -1.0f);
        CHECK(b[0] == -1.0f);
    }
    // UNORM8 uses the correctly rounded division c / 255, not c * (1/255).
    const uint8_t code[2] = {3, 0};
    float out[3];
    DecodeVertex(*FindVertexFormat(VK_FORMAT_R8G8_UNORM), code, out);
    CHECK(out[0] == 3.0f / 255.0f);
}

TEST_CASE("T10: strides, offsets and limits are honoured; nothing outside the data is read", "[classify][T10]") {
    std::vector<float> verts = {0, 0, 0, 1, 0, 0, 0, 1, 0, 5, 5, 5};
    TriangleGeometryView v;
    v.vertexData = verts.data();
    v.vertexDataBytes = verts.size() * 4;
    v.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    v.maxVertex = 3;
    v.range.primitiveCount = 4;
    SECTION("stride 0: every vertex is the same, so every triangle is degenerate") {
        v.vertexStride = 0;
        const ClassifyResult r = ClassifyTriangles(v, nullptr, nullptr);
        CHECK(r.degenerate == 4);
        CHECK(r.unreadable == 0);
    }
    SECTION("overlapping vertices: stride of one component") {
        v.vertexStride = 4;
        v.range.primitiveCount = 3;  // reads up to byte 4*8+12 = 44 <= 48
        v.maxVertex = 8;
        const ClassifyResult r = ClassifyTriangles(v, nullptr, nullptr);
        CHECK(r.unreadable == 0);
        CHECK(r.active == 3);
    }
    SECTION("data too short: the rest is unreadable (recorded active), counted, never read") {
        v.vertexStride = 12;
        v.range.primitiveCount = 2;  // needs 6 vertices, 4 provided
        v.maxVertex = 5;
        uint8_t s[2];
        const ClassifyResult r = ClassifyTriangles(v, nullptr, s);
        CHECK(r.unreadable == 1);
        CHECK(r.firstUnreadable == 1);
        CHECK(s[1] == (kStateActive | kStateUnreadable));
    }
    SECTION("primitiveOffset and firstVertex at their limits") {
        v.vertexStride = 12;
        v.range = {1, 0xFFFFFFF0u, 0xFFFFFFFFu, 0};
        v.maxVertex = 0xFFFFFFFFu;
        const ClassifyResult r = ClassifyTriangles(v, nullptr, nullptr);
        CHECK(r.unreadable == 1);
        CHECK(r.overMaxVertex == 1);
    }
    SECTION("an index above maxVertex is counted (VUID 10774) and an index outside the data is unreadable") {
        const uint32_t idx[] = {0, 1, 3, 0, 1, 0xFFFFFFFFu};
        v.vertexStride = 12;
        v.indexType = VK_INDEX_TYPE_UINT32;
        v.indexData = idx;
        v.indexDataBytes = sizeof idx;
        v.maxVertex = 2;
        v.range = {3, 0, 0, 0};  // the third triangle has no index bytes
        const ClassifyResult r = ClassifyTriangles(v, nullptr, nullptr);
        CHECK(r.overMaxVertex == 2);
        CHECK(r.firstOverMaxVertex == 0);
        CHECK(r.unreadable == 2);
        CHECK(r.indexHashPartial);
    }
    SECTION("non-indexed range past maxVertex (VUID 10775)") {
        v.vertexStride = 12;
        v.range = {1, 0, 1, 0};
        v.maxVertex = 2;
        CHECK(ClassifyTriangles(v, nullptr, nullptr).overMaxVertex == 1);
        v.maxVertex = 3;
        CHECK(ClassifyTriangles(v, nullptr, nullptr).overMaxVertex == 0);
    }
    SECTION("unsupported format and index type classify nothing") {
        v.vertexFormat = VK_FORMAT_R8_UNORM;
        CHECK(ClassifyTriangles(v, nullptr, nullptr).status == ClassifyStatus::UnsupportedFormat);
        v.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
        v.indexType = VkIndexType(12345);
        CHECK(ClassifyTriangles(v, nullptr, nullptr).status == ClassifyStatus::UnsupportedIndexType);
    }
}

TEST_CASE("T11: a NaN in the transform leaves activity to the untransformed X (decision) and warns", "[classify][T11]") {
    float xf[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    xf[0] = Bits(0x7FC00000u);
    Classified c = RunF32({kGood, kGood}, xf);
    CHECK(c.result.active == 2);
    CHECK(c.result.transformHasNaN);
    // Degeneracy is tested before the transform (decision): a singular transform does not make it degenerate.
    const float singular[12] = {0, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0, 3};
    Classified d = RunF32({kGood}, singular);
    CHECK(d.result.degenerate == 0);
    // A transform pointer whose 48 bytes are not provided is reported, and classification still happens.
    TriangleGeometryView v;
    v.vertexData = &kGood;
    v.vertexDataBytes = sizeof kGood;
    v.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    v.vertexStride = 12;
    v.maxVertex = 2;
    v.transformData = xf;
    v.transformDataBytes = 48;
    v.range = {1, 0, 0, 16};
    const ClassifyResult r = ClassifyTriangles(v, nullptr, nullptr);
    CHECK(r.transformUnreadable);
    CHECK(r.active == 1);
}

TEST_CASE("A1/A2: AABB activity, undefined NaN, degenerate points and invalid boxes", "[classify][A1][A2]") {
    struct Box { float v[6]; uint32_t pad[2]; };  // stride 32: the builder must use the stride
    const float nan = Bits(0xFFC00001u);
    std::vector<Box> boxes = {
        {{nan, 0, 0, 1, 1, 1}, {}},  // minX NaN: inactive
        {{0, nan, 0, 1, 1, 1}, {}},  // NaN elsewhere: active, undefined
        {{2, 2, 2, 2, 2, 2}, {}},    // point: degenerate
        {{0, 0, 0, 1, 0, 0}, {}},    // flat on two axes: active, not degenerate
        {{1, 0, 0, 0, 1, 1}, {}},    // min > max: invalid (VUID minX-03546)
        {{0, 0, 0, 1, 1, 1}, {}},
    };
    AabbGeometryView v;
    v.data = boxes.data();
    v.dataBytes = boxes.size() * sizeof(Box) - 8;  // the last record's padding is not provided: still readable
    v.stride = sizeof(Box);
    v.range.primitiveCount = uint32_t(boxes.size());
    uint8_t s[6];
    ActivityRecord rec;
    const ClassifyResult r = ClassifyAabbs(v, &rec, s);
    CHECK(r.inactive == 1);
    CHECK(s[0] == 0);
    CHECK(s[1] == (kStateActive | kStateUndefined));
    CHECK(s[2] == (kStateActive | kStateDegenerate));
    CHECK(s[3] == kStateActive);
    CHECK(s[4] == (kStateActive | kStateInvalidAabb));
    CHECK(r.firstInvalidAabb == 4);
    CHECK(r.unreadable == 0);
    CHECK(rec.activeCount == 5);
    CHECK(!rec.IsActive(0));
}

TEST_CASE("I1/I2: instance reference 0 is inactive; mask 0 is active; array of pointers", "[classify][I1][I2]") {
    VkAccelerationStructureInstanceKHR inst[4] = {};
    inst[0].accelerationStructureReference = 0;          // inactive
    inst[1].accelerationStructureReference = 0x1000;
    inst[1].mask = 0;                                    // still active
    inst[2].accelerationStructureReference = 0x2000;
    inst[2].mask = 0xFF;
    inst[3].accelerationStructureReference = 0;
    InstanceGeometryView v;
    v.data = inst;
    v.dataBytes = sizeof inst;
    v.range.primitiveCount = 4;
    ActivityRecord rec;
    ClassifyResult r = ClassifyInstances(v, &rec, nullptr);
    CHECK(r.active == 2);
    CHECK(!rec.IsActive(0));
    CHECK(rec.IsActive(1));
    const void* ptrs[5] = {&inst[2], &inst[0], nullptr, &inst[1], &inst[2]};
    v.data = ptrs;
    v.dataBytes = sizeof ptrs;
    v.arrayOfPointers = true;
    v.range = {4, 8, 0, 0};  // primitiveOffset skips the first pointer
    uint8_t s[4];
    r = ClassifyInstances(v, &rec, s);
    CHECK(s[0] == 0);
    CHECK(s[1] == (kStateActive | kStateUnreadable));
    CHECK(r.nullInstancePointer == 1);
    CHECK(s[2] == kStateActive);
    CHECK(s[3] == kStateActive);
}

TEST_CASE("N2: zero primitives give an empty record", "[classify][N2]") {
    TriangleGeometryView v;
    v.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    ActivityRecord rec;
    const ClassifyResult r = ClassifyTriangles(v, &rec, nullptr);
    CHECK(r.status == ClassifyStatus::Ok);
    CHECK(rec.primitiveCount == 0);
    CHECK(rec.activeBits.empty());
}
