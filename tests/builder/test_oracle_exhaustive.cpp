// Exhaustive oracle comparison: every code of every component slot, for every vertex format.
// Each (code, slot) appears in several triangles whose other components are drawn from a small pool that
// includes the code itself, +0/-0 and the format's clamp codes, so equality (degeneracy) is exercised
// as often as inequality. Run non-indexed, indexed (uint32, with firstVertex) and with a NaN transform.
#include <catch2/catch_test_macros.hpp>
#include <catch2/generators/catch_generators.hpp>

#include "asval/builder/vertex_format.h"
#include "test_support.h"

using namespace asval::builder;
using testsupport::Rng;

namespace {

// Codes the format treats specially: signed zero, clamps, infinities, the top code.
std::vector<uint32_t> SpecialCodes(const VertexFormatInfo& f) {
    switch (f.kind) {
        case ComponentKind::Float32: return {0u, 0x80000000u, 0x3F800000u, 0x7F800000u, 0x7FC00000u};
        case ComponentKind::Float16: return {0u, 0x8000u, 0x3C00u, 0x7C00u, 0x7E00u};
        case ComponentKind::Snorm:
            return f.componentBits == 8 ? std::vector<uint32_t>{0x80u, 0x81u, 0u, 0x7Fu}
                                        : std::vector<uint32_t>{0x8000u, 0x8001u, 0u, 0x7FFFu};
        default: return {0u, (1u << f.componentBits) - 1, 1u};
    }
}

struct Geometry {
    std::vector<uint8_t> vertices;
    std::vector<uint32_t> indices;
    uint64_t stride = 0;
    uint32_t triangles = 0;
};

constexpr int kTemplates = 3;

// Builds triangles for codes [first, first+count) of every slot; code space of `bits` bits.
Geometry BuildExhaustive(const VertexFormatInfo& f, uint64_t codeCount, uint64_t codeStep, uint64_t seed) {
    Geometry g;
    const int xyz = f.componentCount >= 3 ? 3 : 2;
    const int slots = 3 * xyz;
    g.stride = f.vertexBytes + 4;  // padding between vertices: the builder must honour the stride
    const uint64_t codes = (codeCount + codeStep - 1) / codeStep;
    g.triangles = uint32_t(codes * uint64_t(slots) * kTemplates);
    g.vertices.assign(size_t(g.triangles) * 3 * g.stride, 0xA5);
    const std::vector<uint32_t> special = SpecialCodes(f);
    Rng rng(seed);
    const uint32_t codeMask = f.componentBits >= 32 ? 0xFFFFFFFFu : (1u << f.componentBits) - 1;
    uint32_t t = 0;
    for (uint64_t ci = 0; ci < codes; ++ci) {
        const uint32_t code = uint32_t(ci * codeStep);
        for (int slot = 0; slot < slots; ++slot) {
            for (int k = 0; k < kTemplates; ++k, ++t) {
                uint8_t* tri = g.vertices.data() + size_t(t) * 3 * g.stride;
                for (int v = 0; v < 3; ++v) {
                    if (f.componentCount == 4 && f.kind != ComponentKind::Unorm1010102) {
                        // W is ignored: fill it with a NaN-looking pattern that must not matter.
                        std::memset(tri + v * g.stride + (f.vertexBytes / 4) * 3, 0xFF, f.vertexBytes / 4);
                    }
                    for (int c = 0; c < xyz; ++c) {
                        uint32_t pick;
                        switch (rng.Below(k == 0 ? 6 : 3)) {
                            case 0: pick = code; break;  // equal to the varied code
                            case 1: pick = special[rng.Below(uint32_t(special.size()))]; break;
                            case 2: pick = (v > 0 && k == 2) ? 0u : uint32_t(rng.Next()) & codeMask; break;
                            default: pick = uint32_t(rng.Next()) & codeMask; break;
                        }
                        testsupport::WriteComponent(f.format, tri + v * g.stride, c, pick);
                    }
                }
                if (k == 1) {  // start from two identical vertices: only the varied slot can separate them
                    std::memcpy(tri + g.stride, tri, g.stride);
                }
                testsupport::WriteComponent(f.format, tri + (slot / xyz) * g.stride, slot % xyz, code);
            }
        }
    }
    return g;
}

void CheckAllModes(const VertexFormatInfo& f, Geometry& g) {
    // Non-indexed, with a primitiveOffset of one vertex and firstVertex 1.
    {
        std::vector<uint8_t> shifted(g.vertices.size() + 3 * g.stride);
        std::memcpy(shifted.data() + 3 * g.stride, g.vertices.data(), g.vertices.size());
        TriangleGeometryView view;
        view.vertexData = shifted.data();
        view.vertexDataBytes = shifted.size();
        view.vertexFormat = f.format;
        view.vertexStride = g.stride;
        view.maxVertex = g.triangles * 3 + 2;
        view.range = {g.triangles, uint32_t(2 * g.stride), 1, 0};
        const auto m = testsupport::CompareWithOracle(view);
        INFO("non-indexed: " << m.first);
        CHECK(m.count == 0);
    }
    // Indexed (uint32), reversed triangle order, firstVertex 0, with a transform holding a NaN.
    {
        g.indices.resize(size_t(g.triangles) * 3);
        for (uint32_t t = 0; t < g.triangles; ++t)
            for (uint32_t k = 0; k < 3; ++k) g.indices[3 * t + k] = 3 * (g.triangles - 1 - t) + (2 - k);
        float transform[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
        const uint32_t nanBits = 0x7F800001u;
        std::memcpy(&transform[3], &nanBits, 4);
        TriangleGeometryView view;
        view.vertexData = g.vertices.data();
        view.vertexDataBytes = g.vertices.size();
        view.vertexFormat = f.format;
        view.vertexStride = g.stride;
        view.maxVertex = g.triangles * 3 - 1;
        view.indexType = VK_INDEX_TYPE_UINT32;
        view.indexData = g.indices.data();
        view.indexDataBytes = g.indices.size() * 4;
        view.transformData = transform;
        view.transformDataBytes = sizeof transform;
        view.range = {g.triangles, 0, 0, 0};
        const auto m = testsupport::CompareWithOracle(view);
        INFO("indexed: " << m.first);
        CHECK(m.count == 0);
        const ClassifyResult r = ClassifyTriangles(view, nullptr, nullptr);
        CHECK(r.transformHasNaN);
    }
}

}  // namespace

namespace {

template <typename Pick>
void RunExhaustive(Pick pick) {
    int formats = 0;
    for (const VertexFormatInfo* f = VertexFormatsBegin(); f != VertexFormatsEnd(); ++f) {
        if (!pick(*f)) continue;
        ++formats;
        INFO("format " << int(f->format));
        // 8/10/16-bit formats: every code. Float32: every (2^16+1)-th code; the random test
        // (test_oracle_random.cpp) covers float32 bit patterns in depth.
        const uint64_t codeCount = f->componentBits >= 32 ? (uint64_t(1) << 32) : (uint64_t(1) << f->componentBits);
        const uint64_t step = f->componentBits >= 32 ? (uint64_t(1) << 16) + 1 : 1;
        Geometry g = BuildExhaustive(*f, codeCount, step, 1234 + uint64_t(f->format));
        CheckAllModes(*f, g);
    }
    CHECK(formats > 0);
}

}  // namespace

// Split in three so ctest can run them in parallel.
TEST_CASE("every half encoding in every component slot matches the oracle", "[oracle][exhaustive]") {
    RunExhaustive([](const VertexFormatInfo& f) { return f.kind == ComponentKind::Float16 || f.kind == ComponentKind::Float32; });
}

TEST_CASE("every 16-bit normalized code in every component slot matches the oracle", "[oracle][exhaustive]") {
    RunExhaustive([](const VertexFormatInfo& f) {
        return (f.kind == ComponentKind::Snorm || f.kind == ComponentKind::Unorm) && f.componentBits == 16;
    });
}

TEST_CASE("every 8 and 10-bit normalized code in every component slot matches the oracle", "[oracle][exhaustive]") {
    RunExhaustive([](const VertexFormatInfo& f) {
        return f.kind == ComponentKind::Unorm1010102 ||
               ((f.kind == ComponentKind::Snorm || f.kind == ComponentKind::Unorm) && f.componentBits == 8);
    });
}
