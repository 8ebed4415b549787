// Vertex formats that VK_KHR_acceleration_structure accepts, and how their components decode.
#pragma once

#include <cstdint>
#include <vulkan/vulkan_core.h>

namespace asval::builder {

enum class ComponentKind : uint8_t {
    Float32,     // IEEE binary32
    Float16,     // IEEE binary16
    Snorm,       // max(c / (2^(b-1) - 1), -1)
    Unorm,       // c / (2^b - 1)
    Unorm1010102 // A2B10G10R10_UNORM_PACK32: X = bits 0..9, Y = 10..19, Z = 20..29
};

struct VertexFormatInfo {
    VkFormat format = VK_FORMAT_UNDEFINED;
    ComponentKind kind = ComponentKind::Float32;
    uint8_t componentBits = 0;    // 32, 16, 8 or 10
    uint8_t componentCount = 0;   // 2, 3 or 4 (components beyond Z are ignored; 2-component formats have Z = 0)
    uint8_t vertexBytes = 0;      // bytes read per vertex
    uint8_t componentBytes = 0;   // the "component size" of VUID 03735 / 03657 (packed format: 4)
    bool hasNaN = false;          // false: every triangle is active
    bool mandatory = false;       // VK_FORMAT_FEATURE_ACCELERATION_STRUCTURE_VERTEX_BUFFER_BIT_KHR is required
};

// nullptr if the builder cannot decode `format` (the layer reports it; the build is then not classified).
const VertexFormatInfo* FindVertexFormat(VkFormat format);

// All decodable formats, for tests and benchmarks.
const VertexFormatInfo* VertexFormatsBegin();
const VertexFormatInfo* VertexFormatsEnd();

// Index element size in bytes (0 for VK_INDEX_TYPE_NONE_KHR, -1 for a type the builder does not accept).
int IndexTypeBytes(VkIndexType type);

// Decodes one vertex to floats exactly as the spec's conversion rules say (half is exact; norm formats use
// a correctly rounded division). xyz[2] = 0 for 2-component formats. No NaN test here: see classify.h.
void DecodeVertex(const VertexFormatInfo& info, const void* vertex, float xyz[3]);

}  // namespace asval::builder
