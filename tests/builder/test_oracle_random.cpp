// Randomised oracle comparison on float32 formats: bit patterns weighted toward NaN (every kind),
// +-0, +-inf, subnormals, FLT_MAX and repeated values, with random index types, duplicated indices,
// firstVertex / primitiveOffset, strides and transforms. 2M triangles per CI run; ASVAL_TEST_SCALE=50
// gives the documented 10^8 run.
#include <catch2/catch_test_macros.hpp>

#include "asval/builder/vertex_format.h"
#include "test_support.h"

using namespace asval::builder;
using testsupport::Rng;

namespace {

uint32_t WeightedFloatBits(Rng& rng, const std::vector<uint32_t>& pool) {
    const uint32_t sign = uint32_t(rng.Next() & 1) << 31;
    switch (rng.Below(10)) {
        case 0: return sign | 0x7F800000u | (1u + rng.Below(0x7FFFFFu));                    // any NaN
        case 1: return sign | (rng.Below(2) ? 0x7FC00000u : 0x7F800001u);                    // qNaN / sNaN
        case 2: return sign;                                                                  // +-0
        case 3: return sign | 0x7F800000u;                                                    // +-inf
        case 4: return sign | (1u + rng.Below(0x7FFFFEu));                                    // subnormal
        case 5: return sign | (rng.Below(2) ? 0x7F7FFFFFu : 0x00800000u);                     // FLT_MAX / FLT_MIN
        case 6: case 7: return pool[rng.Below(uint32_t(pool.size()))];                        // repeats
        default: return uint32_t(rng.Next());                                                 // anything
    }
}

}  // namespace

TEST_CASE("random float32 bit patterns match the oracle (indexed, non-indexed, transforms)", "[oracle][random]") {
    const VkFormat formats[] = {VK_FORMAT_R32G32_SFLOAT, VK_FORMAT_R32G32B32_SFLOAT, VK_FORMAT_R32G32B32A32_SFLOAT};
    const VkIndexType indexTypes[] = {VK_INDEX_TYPE_NONE_KHR, VK_INDEX_TYPE_UINT16, VK_INDEX_TYPE_UINT32,
#ifdef VK_EXT_index_type_uint8
                                      VK_INDEX_TYPE_UINT8_EXT
#endif
    };
    const uint64_t batches = 40 * testsupport::TestScale();
    const uint32_t trianglesPerBatch = 50000;
    Rng rng(42);
    uint64_t mismatches = 0, total = 0, inactive = 0, undefined = 0, degenerate = 0;
    std::string first;
    for (uint64_t b = 0; b < batches; ++b) {
        const VertexFormatInfo& f = *FindVertexFormat(formats[b % 3]);
        const VkIndexType it = indexTypes[(b / 3) % (sizeof indexTypes / sizeof indexTypes[0])];
        const int indexBytes = IndexTypeBytes(it);
        const uint64_t stride = f.vertexBytes + 4 * rng.Below(3);
        // Indexed geometry addresses a small vertex pool so indices repeat (same-index triangles).
        const uint32_t vertexCount = indexBytes == 0 ? 3 * trianglesPerBatch + 8
                                   : (indexBytes == 1 ? 256 : 1000 + rng.Below(60000));
        std::vector<uint32_t> pool;
        for (int i = 0; i < 8; ++i) pool.push_back(uint32_t(rng.Next()));
        std::vector<uint8_t> vertices(size_t(vertexCount) * stride + 64);
        for (uint32_t v = 0; v < vertexCount; ++v)
            for (int c = 0; c < (f.componentCount >= 3 ? 3 : 2); ++c)
                testsupport::WriteComponent(f.format, vertices.data() + v * stride, c, WeightedFloatBits(rng, pool));
        TriangleGeometryView view;
        view.vertexData = vertices.data();
        view.vertexDataBytes = vertices.size();
        view.vertexFormat = f.format;
        view.vertexStride = stride;
        view.indexType = it;
        std::vector<uint8_t> indices;
        const uint32_t firstVertex = rng.Below(4);
        if (indexBytes != 0) {
            const uint32_t offset = uint32_t(indexBytes) * rng.Below(5);
            indices.resize(offset + size_t(trianglesPerBatch) * 3 * size_t(indexBytes));
            const uint32_t span = vertexCount - firstVertex;
            for (size_t i = 0; i < size_t(trianglesPerBatch) * 3; ++i) {
                const uint32_t idx = rng.Below(8) == 0 ? uint32_t(i / 3) % span : rng.Below(span);
                for (int k = 0; k < indexBytes; ++k) indices[offset + i * size_t(indexBytes) + size_t(k)] = uint8_t(idx >> (8 * k));
            }
            view.indexData = indices.data();
            view.indexDataBytes = indices.size();
            view.range = {trianglesPerBatch, offset, firstVertex, 0};
            view.maxVertex = vertexCount - 1 - rng.Below(2);  // sometimes one short: VUID 10774 counted
        } else {
            const uint32_t offset = uint32_t(4 * rng.Below(3));
            view.range = {trianglesPerBatch, offset, firstVertex, 0};
            view.maxVertex = firstVertex + 3 * trianglesPerBatch - 1;
        }
        float transform[16];
        for (float& x : transform) {
            const uint32_t bits = WeightedFloatBits(rng, pool);
            std::memcpy(&x, &bits, 4);
        }
        if (rng.Below(2)) {
            view.transformData = transform;
            view.transformDataBytes = sizeof transform;
            view.range.transformOffset = 16 * rng.Below(2);
        }
        const auto m = testsupport::CompareWithOracle(view);
        if (m.count && first.empty()) first = "batch " + std::to_string(b) + " " + m.first;
        mismatches += m.count;
        total += trianglesPerBatch;
        ClassifyResult r = ClassifyTriangles(view, nullptr, nullptr);
        inactive += r.inactive;
        undefined += r.undefinedNaN;
        degenerate += r.degenerate;
    }
    INFO(first);
    CHECK(mismatches == 0);
    // The generator must actually reach every class (a test that cannot fail is no test).
    CHECK(inactive > total / 10);
    CHECK(undefined > total / 100);
    CHECK(degenerate > total / 100);
}
