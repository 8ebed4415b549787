// Activity records: bit layout, CompareActivity against a brute-force comparison, the index hash.
#include <catch2/catch_test_macros.hpp>

#include <cstring>
#include <limits>
#include <vector>

#include "asval/builder/activity_record.h"
#include "asval/builder/classify.h"
#include "asval/builder/index_hash.h"
#include "test_support.h"

using namespace asval::builder;

namespace {

ActivityRecord RecordOf(const std::vector<bool>& active) {
    ActivityRecord r;
    r.primitiveCount = uint32_t(active.size());
    r.activeBits.assign((active.size() + 63) / 64, 0);
    for (size_t i = 0; i < active.size(); ++i)
        if (active[i]) { r.activeBits[i / 64] |= uint64_t(1) << (i % 64); ++r.activeCount; }
    return r;
}

}  // namespace

TEST_CASE("CompareActivity reports exactly the changed primitives, first ones first", "[record]") {
    testsupport::Rng rng(7);
    for (int trial = 0; trial < 300; ++trial) {
        const size_t n = rng.Below(700);
        std::vector<bool> a(n), b(n);
        for (size_t i = 0; i < n; ++i) {
            a[i] = rng.Below(2);
            b[i] = rng.Below(20) == 0 ? !a[i] : a[i];
        }
        ActivityRecord ra = RecordOf(a), rb = RecordOf(b);
        // Garbage past the last primitive must not count as a change.
        if (n % 64) rb.activeBits.back() |= ~((uint64_t(1) << (n % 64)) - 1);
        std::vector<ActivityChange> changes(5);
        const ActivityDiff d = CompareActivity(ra, rb, changes.data(), changes.size());
        std::vector<ActivityChange> expected;
        uint64_t up = 0, down = 0;
        for (size_t i = 0; i < n; ++i)
            if (a[i] != b[i]) {
                expected.push_back({uint32_t(i), bool(b[i])});
                (b[i] ? up : down)++;
            }
        REQUIRE(d.changedCount == expected.size());
        CHECK(d.becameActive == up);
        CHECK(d.becameInactive == down);
        REQUIRE(d.reported == std::min<size_t>(5, expected.size()));
        for (size_t k = 0; k < d.reported; ++k) {
            CHECK(changes[k].primitive == expected[k].primitive);
            CHECK(changes[k].becameActive == expected[k].becameActive);
        }
        CHECK(!d.primitiveCountDiffers);
    }
}

TEST_CASE("U1: a build then an update that flips one triangle inactive is reported at that triangle", "[record][U1]") {
    std::vector<float> v(3 * 3 * 1000);
    for (size_t i = 0; i < v.size(); ++i) v[i] = float(i % 97) + float(i) * 1e-3f;
    TriangleGeometryView view;
    view.vertexData = v.data();
    view.vertexDataBytes = v.size() * 4;
    view.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    view.vertexStride = 12;
    view.maxVertex = 2999;
    view.range.primitiveCount = 1000;
    ActivityRecord built, updated;
    ClassifyTriangles(view, &built, nullptr);
    CHECK(built.HeapBytes() <= (1000 / 8) + 8);  // about one bit per primitive
    v[3 * (3 * 617 + 1)] = std::numeric_limits<float>::quiet_NaN();  // vertex 1 of triangle 617: X = NaN
    v[3 * (3 * 5) + 1] = 1e9f;  // moving a vertex is allowed (a degenerate change is not an activity change)
    ClassifyTriangles(view, &updated, nullptr);
    ActivityChange ch[4];
    const ActivityDiff d = CompareActivity(built, updated, ch, 4);
    CHECK(d.changedCount == 1);
    CHECK(d.becameInactive == 1);
    REQUIRE(d.reported == 1);
    CHECK(ch[0].primitive == 617);
    CHECK(!ch[0].becameActive);
}

TEST_CASE("index hash: any single changed index value changes the hash; equal inputs hash equal", "[record][hash]") {
    testsupport::Rng rng(99);
    for (int trial = 0; trial < 2000; ++trial) {
        const size_t n = 1 + rng.Below(300);
        std::vector<uint32_t> idx(n);
        for (auto& x : idx) x = uint32_t(rng.Next());
        const Hash128 h = HashIndexBytes(idx.data(), n * 4, 4);
        CHECK(h == HashIndexBytes(idx.data(), n * 4, 4));
        std::vector<uint32_t> changed = idx;
        changed[rng.Below(uint32_t(n))] ^= 1u << rng.Below(32);
        CHECK(h != HashIndexBytes(changed.data(), n * 4, 4));
        CHECK(h != HashIndexBytes(idx.data(), n * 4, 2));        // index type is part of the key
        if (n > 1) CHECK(h != HashIndexBytes(idx.data(), n * 4 - 4, 4));  // length matters
        if (n > 1 && idx[0] != idx[n - 1]) {                      // order matters
            std::swap(changed[0], changed[n - 1]);
            changed = idx;
            std::swap(changed[0], changed[n - 1]);
            CHECK(h != HashIndexBytes(changed.data(), n * 4, 4));
        }
    }
}

TEST_CASE("index hash: block hashes added as stored bytes combine as added one by one", "[record][hash]") {
    // What the layer reads back from the device (16 bytes per block, lo then hi), in batches of every size after
    // an even or an odd number of hashes added singly.
    testsupport::Rng rng(27);
    for (uint32_t before = 0; before < 3; ++before) {
        for (uint32_t count = 0; count < 7; ++count) {
            std::vector<Hash128> blocks(before + count);
            for (Hash128& b : blocks) b = {rng.Next(), rng.Next()};
            std::vector<uint8_t> stored(16 * size_t(count));
            for (uint32_t k = 0; k < count; ++k) {
                std::memcpy(stored.data() + 16 * k, &blocks[before + k].lo, 8);
                std::memcpy(stored.data() + 16 * k + 8, &blocks[before + k].hi, 8);
            }
            IndexHashCombiner one_by_one(2), batched(2);
            for (const Hash128& b : blocks) one_by_one.Add(b);
            for (uint32_t k = 0; k < before; ++k) batched.Add(blocks[k]);
            batched.AddHashes(stored.data(), count);
            CAPTURE(before, count);
            CHECK(batched.Finish(1000) == one_by_one.Finish(1000));
        }
    }
}

TEST_CASE("record through ClassifyTriangles: index hash set for indexed geometry only", "[record][hash]") {
    const float v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    uint16_t idx[3] = {0, 1, 2};
    TriangleGeometryView view;
    view.vertexData = v;
    view.vertexDataBytes = sizeof v;
    view.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    view.vertexStride = 12;
    view.maxVertex = 2;
    view.range.primitiveCount = 1;
    ActivityRecord a, b;
    ClassifyTriangles(view, &a, nullptr);
    CHECK(!a.hasIndexHash);
    view.indexType = VK_INDEX_TYPE_UINT16;
    view.indexData = idx;
    view.indexDataBytes = sizeof idx;
    ClassifyTriangles(view, &a, nullptr);
    CHECK(a.hasIndexHash);
    idx[2] = 1;
    ClassifyTriangles(view, &b, nullptr);
    ActivityChange ch[1];
    CHECK(CompareActivity(a, b, ch, 1).indexHashDiffers);
    CHECK(CompareActivity(a, b, ch, 1).changedCount == 0);
}

TEST_CASE("the classifier's chunked index hash equals the one-shot hash over the whole range", "[record][hash]") {
    testsupport::Rng rng(3);
    for (int trial = 0; trial < 12; ++trial) {
        const uint32_t n = 1 + rng.Below(20000);
        const int indexBytes = trial % 3 == 0 ? 1 : trial % 3 == 1 ? 2 : 4;
        const VkIndexType type = indexBytes == 2 ? VK_INDEX_TYPE_UINT16 : indexBytes == 4 ? VK_INDEX_TYPE_UINT32 : VK_INDEX_TYPE_UINT8_EXT;
        const uint32_t offset = uint32_t(indexBytes) * rng.Below(7);
        std::vector<uint8_t> idx(offset + size_t(n) * 3 * size_t(indexBytes));
        for (auto& b : idx) b = uint8_t(rng.Below(indexBytes == 1 ? 200 : 4));  // small values: indices < 1024
        std::vector<float> v(3 * 70000, 1.0f);
        TriangleGeometryView view;
        view.vertexData = v.data();
        view.vertexDataBytes = v.size() * 4;
        view.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
        view.vertexStride = 12;
        view.maxVertex = 69999;
        view.indexType = type;
        view.indexData = idx.data();
        view.indexDataBytes = idx.size();
        view.range = {n, offset, 0, 0};
        ActivityRecord rec;
        ClassifyTriangles(view, &rec, nullptr);
        REQUIRE(rec.hasIndexHash);
        CHECK(rec.indexHash == HashIndexBytes(idx.data() + offset, size_t(n) * 3 * size_t(indexBytes), uint64_t(indexBytes)));
    }
}
