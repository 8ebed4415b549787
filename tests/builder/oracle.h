// Independent brute-force oracle, written from the spec text and the IEEE 754 / fixed-point definitions.
// It shares no code with the builder: its own format table, its own bit-field decoding into long double,
// its own reading of primitiveOffset / firstVertex / index rules. Slow on purpose (obvious over fast).
#pragma once

#include <cstdint>
#include <vector>
#include <vulkan/vulkan_core.h>

namespace oracle {

struct Component {
    long double value = 0;  // exact decoded value (meaningless when nan)
    bool nan = false;
};

struct Vertex {
    Component c[3];  // X, Y, Z (Z = 0 for two-component formats)
};

// Decodes one vertex of `format` at `p`. Returns false for formats the oracle does not know.
bool DecodeVertex(VkFormat format, const uint8_t* p, Vertex* out);
// True when the format can represent NaN ("If the vertex format does not have a NaN representation...").
bool FormatHasNaN(VkFormat format);
unsigned VertexBytes(VkFormat format);

struct Triangle {
    bool active = true;
    bool degenerate = false;   // only meaningful when active
    bool sameIndex = false;    // "the same index value for more than one vertex"
    bool undefined = false;    // NaN in a non-X component, X not NaN
    bool overMaxVertex = false;
};

struct TriangleInput {
    VkFormat format;
    const uint8_t* vertexData;
    uint64_t stride;
    uint32_t maxVertex;
    VkIndexType indexType;
    const uint8_t* indexData;  // may be null when indexType is NONE
    uint32_t primitiveOffset, firstVertex;
};

// Classifies triangle `t` per "Inactive Primitives and Instances" / "Degenerate Primitives and Instances".
Triangle ClassifyTriangle(const TriangleInput& in, uint32_t t);

// VK_NV_ray_tracing_motion_blur triangles: `vertexData1` holds the positions at time 1.0 ("indexing ... is
// equivalent to the basic vertex position data"); positions interpolate linearly in between. The project's
// decision for the spec's silence: the six vertices are all "vertices" of the triangle, so inactive iff an
// X at either time is NaN, undefined iff a Y/Z at either time is NaN (X not), and degenerate iff the
// triangle is degenerate at every time in [0, 1].
Triangle ClassifyMotionTriangle(const TriangleInput& in, const uint8_t* vertexData1, uint32_t t);

// Activity of record i of a plain VkAccelerationStructureMotionInstanceNV array ("stride of 160 bytes")
// starting at `primitiveOffset`: 1 active, 0 inactive ("acceleration structure reference is 0"), -1 when
// the type is not one of the three the spec defines.
int MotionInstanceActivity(const uint8_t* data, uint32_t primitiveOffset, uint32_t i);

}  // namespace oracle
