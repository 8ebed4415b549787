// VK_NV_ray_tracing_motion_blur activity: motion instances (which reference field, the 160-byte stride,
// array-of-pointers type bits) and motion triangles (the decision for vertex data at time 1), against
// hand-made cases and the independent oracle.
#include <catch2/catch_test_macros.hpp>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "asval/builder/build_input.h"
#include "asval/builder/classify.h"
#include "oracle.h"
#include "test_support.h"

using namespace asval::builder;
using testsupport::Rng;

namespace {

constexpr float kNaN = NAN;

// A plain array of motion records at the spec's stride of 160 bytes.
struct MotionArray {
    std::vector<uint8_t> bytes;
    explicit MotionArray(uint32_t n) : bytes(160ull * n, 0) {}
    uint8_t* At(uint32_t i) { return bytes.data() + 160ull * i; }
    template <typename T>
    void Put(uint32_t i, uint32_t type, const T& body, uint32_t flags = 0) {
        std::memcpy(At(i), &type, 4);
        std::memcpy(At(i) + 4, &flags, 4);
        std::memcpy(At(i) + 8, &body, sizeof body);
    }
};

VkAccelerationStructureInstanceKHR Static(uint64_t ref) {
    VkAccelerationStructureInstanceKHR s = {};
    s.transform.matrix[0][0] = s.transform.matrix[1][1] = s.transform.matrix[2][2] = 1;
    s.accelerationStructureReference = ref;
    return s;
}

}  // namespace

TEST_CASE("motion instances: the reference field of each type decides activity; stride 160", "[classify][motion]") {
    MotionArray a(6);
    a.Put(0, VK_ACCELERATION_STRUCTURE_MOTION_INSTANCE_TYPE_STATIC_NV, Static(0));  // inactive
    VkAccelerationStructureMatrixMotionInstanceNV m = {};
    m.transformT0.matrix[0][0] = kNaN;  // NaN in a transform: still active (only the reference counts)
    m.accelerationStructureReference = 7;
    m.mask = 0;                          // mask 0: active
    a.Put(1, VK_ACCELERATION_STRUCTURE_MOTION_INSTANCE_TYPE_MATRIX_MOTION_NV, m);
    VkAccelerationStructureSRTMotionInstanceNV s = {};
    s.accelerationStructureReference = 0;
    a.Put(2, VK_ACCELERATION_STRUCTURE_MOTION_INSTANCE_TYPE_SRT_MOTION_NV, s);  // inactive
    // A matrix record whose bytes at the *static* reference offset (56 into data) are non-zero but whose
    // own reference (offset 104) is 0: inactive. Pins which field is read.
    VkAccelerationStructureMatrixMotionInstanceNV m2 = {};
    m2.transformT1.matrix[0][1] = 1.0f;  // bytes 52..55 of data; and 56..59:
    std::memcpy(reinterpret_cast<uint8_t*>(&m2) + 56, "\x01\x02\x03\x04", 4);
    a.Put(3, VK_ACCELERATION_STRUCTURE_MOTION_INSTANCE_TYPE_MATRIX_MOTION_NV, m2);
    a.Put(4, 7u, Static(5));                                                          // invalid type
    a.Put(5, VK_ACCELERATION_STRUCTURE_MOTION_INSTANCE_TYPE_STATIC_NV, Static(9), 1u);  // flags != 0
    InstanceGeometryView v;
    v.data = a.bytes.data();
    v.dataBytes = a.bytes.size();
    v.motionInstances = true;
    v.range.primitiveCount = 6;
    ActivityRecord rec;
    uint8_t st[6];
    ClassifyResult r = ClassifyInstances(v, &rec, st);
    CHECK(st[0] == 0);
    CHECK(st[1] == kStateActive);
    CHECK(st[2] == 0);
    CHECK(st[3] == 0);
    CHECK(st[4] == (kStateActive | kStateUnreadable));
    CHECK(st[5] == kStateActive);
    CHECK(r.invalidMotionType == 1);
    CHECK(r.firstInvalidMotionType == 4);
    CHECK(r.unreadable == 1);
    CHECK(r.nonZeroMotionFlags == 1);
    CHECK(rec.activeCount == 3);
    CHECK(!rec.IsActive(0));
    CHECK(rec.IsActive(1));
    // The last record needs its 152 bytes (not the 160 of the stride); one byte fewer is unreadable.
    v.dataBytes = 160 * 5 + 152;
    r = ClassifyInstances(v, nullptr, st);
    CHECK(r.unreadable == 1);
    CHECK(st[5] == kStateActive);
    v.dataBytes = 160 * 5 + 151;
    r = ClassifyInstances(v, nullptr, st);
    CHECK(st[5] == (kStateActive | kStateUnreadable));
    CHECK(r.firstUnreadable == 4);
    CHECK(r.unreadable == 2);
    // primitiveOffset is in bytes: 160 skips record 0.
    v.dataBytes = a.bytes.size();
    v.range = {2, 160, 0, 0};
    r = ClassifyInstances(v, nullptr, st);
    CHECK(st[0] == kStateActive);
    CHECK(st[1] == 0);
}

TEST_CASE("motion instances: array of pointers carries the type in the low 4 bits", "[classify][motion]") {
    alignas(16) VkAccelerationStructureInstanceKHR st0 = Static(3);
    alignas(16) VkAccelerationStructureMatrixMotionInstanceNV mm = {};
    mm.accelerationStructureReference = 0;  // inactive
    alignas(16) VkAccelerationStructureSRTMotionInstanceNV ss = {};
    ss.accelerationStructureReference = 11;
    auto tagged = [](const void* p, uintptr_t type) { return reinterpret_cast<const void*>(reinterpret_cast<uintptr_t>(p) | type); };
    const void* ptrs[6] = {tagged(&st0, 0), tagged(&mm, 1), tagged(&ss, 2), tagged(nullptr, 2), tagged(&ss, 5),
                           tagged(&mm, 2)};  // the last: matrix bytes read as SRT (reference at 136: past mm)
    InstanceGeometryView v;
    v.data = ptrs;
    v.dataBytes = sizeof(const void*) * 5;  // the sixth pointer is not provided
    v.arrayOfPointers = true;
    v.motionInstances = true;
    v.range.primitiveCount = 6;
    uint8_t s[6];
    const ClassifyResult r = ClassifyInstances(v, nullptr, s);
    CHECK(s[0] == kStateActive);
    CHECK(s[1] == 0);
    CHECK(s[2] == kStateActive);
    CHECK(s[3] == (kStateActive | kStateUnreadable));
    CHECK(s[4] == (kStateActive | kStateUnreadable));
    CHECK(s[5] == (kStateActive | kStateUnreadable));
    CHECK(r.nullInstancePointer == 1);
    CHECK(r.invalidMotionType == 1);
    CHECK(r.unreadable == 3);
    CHECK(r.active == 5);
}

TEST_CASE("motion instances: random plain arrays against the oracle", "[classify][motion][oracle]") {
    Rng rng(99);
    uint64_t mismatches = 0, inactive = 0, invalid = 0;
    const uint32_t rounds = 200 * uint32_t(testsupport::TestScale());
    for (uint32_t round = 0; round < rounds; ++round) {
        const uint32_t n = 1 + rng.Below(64), skip = rng.Below(3);
        MotionArray a(n + skip);
        for (uint8_t& b : a.bytes) b = uint8_t(rng.Below(4) == 0 ? rng.Next() : 0);  // sparse noise
        for (uint32_t i = 0; i < n + skip; ++i) {
            const uint32_t type = rng.Below(16) == 0 ? 3 + rng.Below(100) : rng.Below(3);
            std::memcpy(a.At(i), &type, 4);
            const uint32_t at = type == 0 ? 64 : type == 1 ? 112 : 144;
            if (type <= 2) {
                const uint64_t ref = rng.Below(3) == 0 ? 0 : rng.Next();
                std::memcpy(a.At(i) + at, &ref, 8);
            }
        }
        InstanceGeometryView v;
        v.data = a.bytes.data();
        v.dataBytes = a.bytes.size();
        v.motionInstances = true;
        v.range = {n, 160 * skip, 0, 0};
        std::vector<uint8_t> st(n);
        ActivityRecord rec;
        ClassifyInstances(v, &rec, st.data());
        for (uint32_t i = 0; i < n; ++i) {
            const int o = oracle::MotionInstanceActivity(a.bytes.data(), 160 * skip, i);
            const uint8_t want = o < 0 ? uint8_t(kStateActive | kStateUnreadable) : o ? uint8_t(kStateActive) : uint8_t(0);
            mismatches += st[i] != want || rec.IsActive(i) != (o != 0);
            inactive += o == 0;
            invalid += o < 0;
        }
    }
    CHECK(mismatches == 0);
    CHECK(inactive > 100);
    CHECK(invalid > 10);
}

TEST_CASE("motion triangles: hand cases of the decision", "[classify][motion]") {
    // Six triangles, non-indexed; v0 = time 0, v1 = time 1.
    const float base[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    std::vector<float> v0, v1;
    auto add = [&](const float* a, const float* b) { v0.insert(v0.end(), a, a + 9); v1.insert(v1.end(), b, b + 9); };
    float t[9];
    std::memcpy(t, base, sizeof t); t[3] = kNaN;  // 0: X NaN at time 1 only -> inactive
    add(base, t);
    std::memcpy(t, base, sizeof t); t[4] = kNaN;  // 1: Y NaN at time 1 only -> active, undefined
    add(base, t);
    float d0[9] = {0, 0, 0, 0, 0, 0, 5, 6, 7};    // 2: v0 == v1 at time 0 ...
    float d1[9] = {2, 2, 2, 2, 2, 2, 1, 1, 1};    //    ... and at time 1: degenerate at every t
    add(d0, d1);
    float e1[9] = {4, 4, 4, 8, 8, 8, 8, 8, 8};    // 3: v0 == v1 at time 0, v1 == v2 at time 1: not degenerate
    add(d0, e1);
    float f0[9] = {1, 2, 0, 1, 2, 5, 1, 2, 9};    // 4: X and Y shared at both times (with -0 == +0): degenerate
    float f1[9] = {-0.0f, 3, 1, 0, 3, 2, 0, 3, 4};
    add(f0, f1);
    add(base, base);                               // 5: ordinary, no motion: active
    TriangleGeometryView v;
    v.vertexData = v0.data();
    v.vertexDataBytes = v0.size() * 4;
    v.motionVertexData = v1.data();
    v.motionVertexDataBytes = v1.size() * 4;
    v.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    v.vertexStride = 12;
    v.maxVertex = 17;
    v.range.primitiveCount = 6;
    uint8_t s[6];
    ActivityRecord rec;
    ClassifyResult r = ClassifyTriangles(v, &rec, s);
    CHECK(s[0] == 0);
    CHECK(s[1] == (kStateActive | kStateUndefined));
    CHECK(s[2] == (kStateActive | kStateDegenerate));
    CHECK(s[3] == kStateActive);
    CHECK(s[4] == (kStateActive | kStateDegenerate));
    CHECK(s[5] == kStateActive);
    CHECK(r.inactive == 1);
    CHECK(r.undefinedNaN == 1);
    CHECK(r.firstUndefined == 1);
    CHECK(r.degenerate == 2);
    CHECK(rec.activeCount == 5);
    CHECK(!rec.IsActive(0));
    // Time-1 data missing for the last triangle: unreadable (recorded active), the others unchanged.
    v.motionVertexDataBytes = v1.size() * 4 - 1;
    r = ClassifyTriangles(v, nullptr, s);
    CHECK(s[5] == (kStateActive | kStateUnreadable));
    CHECK(r.unreadable == 1);
    CHECK(r.firstUnreadable == 5);
    CHECK(s[0] == 0);
    // Not discarded without ALLOW_UPDATE: only triangle 3 (degenerate at both ends, not in between) and
    // 5 (readable again) and 1's undefined input is excluded.
    v.motionVertexDataBytes = v1.size() * 4;
    BuildInput in;
    AppendTriangles(v, false, 0, &in);
    CHECK(in.refs.size() == 2);
    CHECK(in.excludedInactive == 1);
    CHECK(in.excludedUndefined == 1);
    CHECK(in.excludedDegenerate == 2);
    // Triangle 3's box spans both times.
    for (const PrimRef& p : in.refs)
        if (p.id == 3) {
            CHECK(p.lo[0] == 0);
            CHECK(p.hi[0] == 8);
            CHECK(p.hi[2] == 8);
        }
}

TEST_CASE("motion triangles: indexed, the index hash and same-index rule are the time-0 pass's", "[classify][motion]") {
    const float pos0[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 1};
    const float pos1[12] = {0, 0, 1, 1, 0, 1, 0, 1, 1, kNaN, 1, 1};
    const uint16_t idx[9] = {0, 1, 2, 0, 0, 2, 1, 2, 3};  // triangle 1: same index; 2 uses vertex 3 (X NaN at time 1)
    TriangleGeometryView v;
    v.vertexData = pos0;
    v.vertexDataBytes = sizeof pos0;
    v.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    v.vertexStride = 12;
    v.maxVertex = 3;
    v.indexType = VK_INDEX_TYPE_UINT16;
    v.indexData = idx;
    v.indexDataBytes = sizeof idx;
    v.range.primitiveCount = 3;
    ActivityRecord still, moving;
    ClassifyTriangles(v, &still, nullptr);
    v.motionVertexData = pos1;
    v.motionVertexDataBytes = sizeof pos1;
    uint8_t s[3];
    ClassifyTriangles(v, &moving, s);
    CHECK(s[0] == kStateActive);
    CHECK(s[1] == (kStateActive | kStateDegenerate | kStateSameIndex));
    CHECK(s[2] == 0);
    CHECK(moving.hasIndexHash);
    CHECK(moving.indexHash == still.indexHash);
    CHECK(still.IsActive(2));
    CHECK(!moving.IsActive(2));
}

TEST_CASE("motion triangles: random inputs against the oracle", "[classify][motion][oracle]") {
    const VkFormat formats[] = {VK_FORMAT_R32G32B32_SFLOAT, VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_R16G16_SNORM,
                                VK_FORMAT_R32G32_SFLOAT};
    const VkIndexType indexTypes[] = {VK_INDEX_TYPE_NONE_KHR, VK_INDEX_TYPE_UINT16, VK_INDEX_TYPE_UINT32, VK_INDEX_TYPE_UINT8_EXT};
    Rng rng(31337);
    uint64_t mismatches = 0, total = 0, inactive = 0, undefined = 0, degenerate = 0, degenerateOneEnd = 0;
    std::string first;
    const uint32_t rounds = 400 * uint32_t(testsupport::TestScale());
    for (uint32_t round = 0; round < rounds; ++round) {
        const VkFormat format = formats[rng.Below(4)];
        const VkIndexType indexType = indexTypes[rng.Below(4)];
        const unsigned vbytes = oracle::VertexBytes(format);
        const int comps = testsupport::StoredXyz(format);
        const uint32_t bits = testsupport::CodeBits(format);
        const uint32_t n = 1 + rng.Below(200), vertices = 8 + rng.Below(8);
        const uint32_t indexed = indexType != VK_INDEX_TYPE_NONE_KHR;
        const uint32_t vcount = indexed ? vertices : 3 * n + 4;
        const uint64_t stride = vbytes + 4 * rng.Below(2);
        std::vector<uint8_t> vb[2];
        // A small pool of component codes (so equalities are frequent), NaN-like codes included.
        std::vector<uint32_t> pool;
        for (int i = 0; i < 6; ++i) pool.push_back(uint32_t(rng.Next()) & (bits == 32 ? 0xFFFFFFFFu : (1u << bits) - 1));
        pool.push_back(0);
        pool.push_back(bits == 32 ? 0x80000000u : bits == 16 ? 0x8000u : 0);              // -0
        pool.push_back(bits == 32 ? 0x7FC00000u : bits == 16 ? 0x7E00u : 0x8000u);        // NaN / SNORM -1 code
        for (int time = 0; time < 2; ++time) {
            vb[time].assign(stride * vcount + 16, 0);
            for (uint32_t vtx = 0; vtx < vcount; ++vtx)
                for (int c = 0; c < comps; ++c) {
                    uint32_t code = pool[rng.Below(uint32_t(pool.size()))];
                    if (time == 1 && rng.Below(3) == 0) {  // time 1 often repeats time 0's code
                        code = 0;
                        std::memcpy(&code, vb[0].data() + stride * vtx + (bits / 8) * unsigned(c), bits / 8);
                    }
                    if (bits == 32 && rng.Below(40) == 0) code = 0x7F800001u;  // sNaN
                    testsupport::WriteComponent(format, vb[time].data() + stride * vtx, c, code);
                }
        }
        const unsigned ib = indexType == VK_INDEX_TYPE_UINT16 ? 2 : indexType == VK_INDEX_TYPE_UINT32 ? 4 : indexed ? 1 : 0;
        std::vector<uint8_t> indices(size_t(3) * n * ib + 8);
        for (uint32_t k = 0; k < 3 * n && ib; ++k) {
            const uint32_t value = rng.Below(vertices - 2);
            std::memcpy(indices.data() + 4 + size_t(k) * ib, &value, ib);  // primitiveOffset 4 (little endian)
        }
        TriangleGeometryView v;
        v.vertexData = vb[0].data();
        v.vertexDataBytes = vb[0].size();
        v.motionVertexData = vb[1].data();
        v.motionVertexDataBytes = vb[1].size();
        v.vertexFormat = format;
        v.vertexStride = stride;
        v.maxVertex = vcount - 1;
        v.indexType = indexType;
        v.indexData = ib ? indices.data() : nullptr;
        v.indexDataBytes = ib ? indices.size() : 0;
        v.range = {n, ib ? 4u : 0u, ib ? 2u : 1u, 0};
        std::vector<uint8_t> st(n);
        ClassifyTriangles(v, nullptr, st.data());
        oracle::TriangleInput oi{format, vb[0].data(), stride, v.maxVertex, indexType, ib ? indices.data() : nullptr,
                                 v.range.primitiveOffset, v.range.firstVertex};
        for (uint32_t t = 0; t < n; ++t) {
            const oracle::Triangle o = oracle::ClassifyMotionTriangle(oi, vb[1].data(), t);
            uint8_t want = 0;
            if (o.active)
                want = uint8_t(kStateActive | (o.degenerate ? kStateDegenerate : 0) | (o.sameIndex ? kStateSameIndex : 0) |
                               (o.undefined ? kStateUndefined : 0));
            ++total;
            if (st[t] != want && mismatches++ == 0)
                first = "format " + std::to_string(int(format)) + " index " + std::to_string(int(indexType)) + " tri " +
                        std::to_string(t) + " got " + std::to_string(st[t]) + " want " + std::to_string(want);
            inactive += !o.active;
            undefined += o.undefined;
            degenerate += o.active && o.degenerate;
            // Degenerate at one end only (by the static oracle): the case the motion rule changes.
            oracle::TriangleInput o1 = oi;
            o1.vertexData = vb[1].data();
            const oracle::Triangle s0 = oracle::ClassifyTriangle(oi, t), s1 = oracle::ClassifyTriangle(o1, t);
            degenerateOneEnd += o.active && !o.degenerate && s0.active && s1.active && (s0.degenerate || s1.degenerate);
        }
    }
    INFO(first);
    CHECK(mismatches == 0);
    CHECK(inactive * 10 > total);
    CHECK(undefined * 100 > total);
    CHECK(degenerate * 100 > total);
    CHECK(degenerateOneEnd * 100 > total);
}
