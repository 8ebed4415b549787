#include "test_support.h"

#include <cstdlib>

#include "asval/builder/vertex_format.h"

namespace testsupport {

uint64_t TestScale() {
    const char* s = std::getenv("ASVAL_TEST_SCALE");
    const long v = s ? std::strtol(s, nullptr, 10) : 1;
    return v > 0 ? uint64_t(v) : 1;
}

int StoredXyz(VkFormat format) {
    const auto* f = asval::builder::FindVertexFormat(format);
    return f->componentCount >= 3 ? 3 : 2;
}

unsigned CodeBits(VkFormat format) { return asval::builder::FindVertexFormat(format)->componentBits; }

void WriteComponent(VkFormat format, uint8_t* vertex, int comp, uint32_t code) {
    const auto* f = asval::builder::FindVertexFormat(format);
    if (f->kind == asval::builder::ComponentKind::Unorm1010102) {
        uint32_t w;
        std::memcpy(&w, vertex, 4);
        w = (w & ~(0x3FFu << (10 * comp))) | ((code & 0x3FFu) << (10 * comp));
        std::memcpy(vertex, &w, 4);
        return;
    }
    const unsigned bytes = f->componentBits / 8;
    for (unsigned i = 0; i < bytes; ++i) vertex[comp * bytes + i] = uint8_t(code >> (8 * i));
}

Mismatch CompareWithOracle(const asval::builder::TriangleGeometryView& view) {
    using namespace asval::builder;
    Mismatch m;
    const uint32_t n = view.range.primitiveCount;
    std::vector<uint8_t> states(n);
    ActivityRecord record;
    const ClassifyResult r = ClassifyTriangles(view, &record, states.data());
    oracle::TriangleInput in{view.vertexFormat, static_cast<const uint8_t*>(view.vertexData), view.vertexStride,
                             view.maxVertex, view.indexType, static_cast<const uint8_t*>(view.indexData),
                             view.range.primitiveOffset, view.range.firstVertex};
    uint32_t active = 0, degenerate = 0, sameIndex = 0, undefined = 0, over = 0;
    auto note = [&](uint32_t t, const char* what) {
        if (m.count++ == 0) m.first = "triangle " + std::to_string(t) + ": " + what;
    };
    for (uint32_t t = 0; t < n; ++t) {
        const oracle::Triangle o = oracle::ClassifyTriangle(in, t);
        const uint8_t s = states[t];
        active += o.active;
        over += o.overMaxVertex;
        if (o.active) {
            degenerate += o.degenerate;
            sameIndex += o.sameIndex;
            undefined += o.undefined;
        }
        if (bool(s & kStateActive) != o.active) { note(t, "active"); continue; }
        if (record.IsActive(t) != o.active) { note(t, "record bit"); continue; }
        if (!o.active) { if (s != 0) note(t, "inactive with flags"); continue; }
        if (bool(s & kStateDegenerate) != o.degenerate) { note(t, "degenerate"); continue; }
        if (bool(s & kStateSameIndex) != o.sameIndex) { note(t, "sameIndex"); continue; }
        if (bool(s & kStateUndefined) != o.undefined) { note(t, "undefined"); continue; }
        if (s & kStateUnreadable) note(t, "unreadable");
    }
    if (r.active != active || record.activeCount != active || r.inactive != n - active) note(n, "active total");
    if (r.degenerate != degenerate) note(n, "degenerate total");
    if (r.sameIndex != sameIndex) note(n, "sameIndex total");
    if (r.undefinedNaN != undefined) note(n, "undefined total");
    if (r.overMaxVertex != over) note(n, "overMaxVertex total");
    return m;
}

}  // namespace testsupport
