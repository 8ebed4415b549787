// Fuzz target: decode + classify + build on arbitrary bytes. The first 32 bytes choose the geometry
// kind, format, index type, stride, offsets, counts and build options; the rest is the data buffer,
// shared by vertices, indices, transform, AABBs and instances. Any crash, sanitizer report or violated
// tree property (checked with the test suite's CheckTree) is a finding.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "asval/builder/bvh_triangles.h"
#include "asval/builder/classify.h"
#include "asval/builder/vertex_format.h"
#include "bvh_checks.h"

using namespace asval::builder;

namespace {

struct Reader {
    const uint8_t* p;
    size_t n;
    uint32_t U32() {
        uint32_t v = 0;
        for (int i = 0; i < 4; ++i) v |= uint32_t(n ? (--n, *p++) : 0) << (8 * i);
        return v;
    }
};

void Require(bool ok, const char* what) {
    if (!ok) {
        std::fprintf(stderr, "fuzz property violated: %s\n", what);
        std::abort();
    }
}

void CheckBuilt(const Bvh& bvh, const BuildInput* input) {
    const auto report = bvhcheck::CheckTree(bvh, input ? bvhcheck::RefsById(*input) : std::vector<PrimRef>{}, 8, input != nullptr);
    if (report.violations) std::fprintf(stderr, "%s\n", report.first.c_str());
    Require(report.violations == 0, "tree properties");
}

BlasSummary Lookup(uint64_t ref, void*) {
    BlasSummary s;
    s.known = (ref & 3) != 3;
    s.activePrimitives = uint32_t(ref & 1);
    float v[6];
    for (int i = 0; i < 6; ++i) {
        const uint32_t bits = uint32_t(ref >> (i * 5)) * 0x9E3779B1u;
        std::memcpy(&v[i], &bits, 4);
        if (v[i] != v[i]) v[i] = 0;  // the layer never stores NaN BLAS boxes
    }
    for (int a = 0; a < 3; ++a) { s.lo[a] = std::min(v[a], v[a + 3]); s.hi[a] = std::max(v[a], v[a + 3]); }
    return s;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    Reader r{data, size < 32 ? size : 32};
    const uint32_t h0 = r.U32(), h1 = r.U32(), h2 = r.U32(), h3 = r.U32(), h4 = r.U32(), h5 = r.U32();
    const uint8_t* body = size > 32 ? data + 32 : nullptr;
    const size_t bodyBytes = size > 32 ? size - 32 : 0;
    // Copy so the body is suitably aligned for nothing in particular: the builder must not care.
    std::vector<uint8_t> buf(body, body + bodyBytes);
    const uint8_t* b = buf.empty() ? nullptr : buf.data();

    BuildOptions o;
    o.mode = (h0 & 1) ? BuildMode::Lbvh : BuildMode::BinnedSah;
    o.bins = 2 + (h0 >> 1) % 63;
    o.maxLeafSize = 1 + (h0 >> 8) % 8;
    o.mortonBitsPerAxis = 1 + (h0 >> 12) % 21;
    o.spatialSplits = SpatialSplits((h0 >> 17) % 3);
    o.threads = 1 + ((h0 >> 19) & 1);
    const bool allowUpdate = (h0 >> 20) & 1;
    const uint32_t kind = (h0 >> 21) % 3;
    BuildRange range{h1 % 4097, h2 % 256, h3 % 64, h4 % 128};

    if (kind == 0) {
        const size_t formats = size_t(VertexFormatsEnd() - VertexFormatsBegin());
        TriangleGeometryView v;
        v.vertexFormat = VertexFormatsBegin()[h5 % formats].format;
        const VkIndexType types[] = {VK_INDEX_TYPE_NONE_KHR, VK_INDEX_TYPE_UINT16, VK_INDEX_TYPE_UINT32,
#ifdef VK_EXT_index_type_uint8
                                     VK_INDEX_TYPE_UINT8_EXT
#endif
        };
        v.indexType = types[(h5 >> 8) % (sizeof types / sizeof types[0])];
        v.vertexStride = (h5 >> 10) % 64;
        v.maxVertex = (h5 >> 16) % 4096;
        v.vertexData = b;
        v.vertexDataBytes = bodyBytes;
        v.indexData = b;
        v.indexDataBytes = bodyBytes;
        if ((h5 >> 28) & 1) { v.transformData = b; v.transformDataBytes = bodyBytes; }
        v.range = range;
        ActivityRecord rec;
        std::vector<uint8_t> states(range.primitiveCount);
        const ClassifyResult cr = ClassifyTriangles(v, &rec, states.data());
        if (cr.status == ClassifyStatus::Ok) Require(cr.active + cr.inactive == range.primitiveCount, "counts");
        BuildInput in;
        AppendTriangles(v, allowUpdate, 0, &in);
        BuildInput copy = in;
        const Bvh plain = BuildBvh(std::move(copy), o);
        CheckBuilt(plain, &in);
        const Bvh split = BuildTriangleBvh(&v, 1, allowUpdate, o);
        CheckBuilt(split, nullptr);
    } else if (kind == 1) {
        AabbGeometryView v;
        v.data = b;
        v.dataBytes = bodyBytes;
        v.stride = h5 % 64;
        v.range = range;
        BuildInput in;
        AppendAabbs(v, allowUpdate, 0, &in);
        BuildInput copy = in;
        CheckBuilt(BuildBvh(std::move(copy), o), &in);
    } else {
        // Plain instances only: arrayOfPointers would need real pointers, which bytes cannot supply.
        InstanceGeometryView v;
        v.data = b;
        v.dataBytes = bodyBytes;
        v.range = range;
        BuildInput in;
        AppendInstances(v, Lookup, nullptr, 0, &in);
        BuildInput copy = in;
        CheckBuilt(BuildBvh(std::move(copy), o), &in);
    }
    return 0;
}

#ifndef ASVAL_LIBFUZZER
// Without libFuzzer (GCC builds): replay files given on the command line, else run N random inputs
// (argv[1] = count, default 2000) so CI still exercises the target.
int main(int argc, char** argv) {
    if (argc > 1 && std::strtol(argv[1], nullptr, 10) == 0) {
        for (int i = 1; i < argc; ++i) {
            FILE* f = std::fopen(argv[i], "rb");
            if (!f) continue;
            std::vector<uint8_t> d;
            int c;
            while ((c = std::fgetc(f)) != EOF) d.push_back(uint8_t(c));
            std::fclose(f);
            LLVMFuzzerTestOneInput(d.data(), d.size());
        }
        return 0;
    }
    const long count = argc > 1 ? std::strtol(argv[1], nullptr, 10) : 2000;
    uint64_t s = 12345;
    for (long i = 0; i < count; ++i) {
        auto next = [&s] { s = s * 6364136223846793005ull + 1442695040888963407ull; return uint32_t(s >> 33); };
        std::vector<uint8_t> d(32 + next() % 4096);
        for (auto& x : d) {
            const uint32_t k = next();
            // Bias toward interesting bytes: 0x00, 0xFF, 0x7F, 0x80 (NaN / inf / sign / limit patterns).
            static const uint8_t kInteresting[4] = {0x00, 0xFF, 0x7F, 0x80};
            x = (k & 7) < 4 ? uint8_t(k >> 8) : kInteresting[(k >> 3) & 3];
        }
        LLVMFuzzerTestOneInput(d.data(), d.size());
    }
    return 0;
}
#endif
