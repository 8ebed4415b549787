// Vertex formats that VK_KHR_acceleration_structure accepts, and how their components decode.
#pragma once

#include <cstdint>
#include <vulkan/vulkan_core.h>

#include "asval/vertex_formats.h"

namespace asval::builder {

// The format facts (sizes, NaN-capable X, decode kind) live in the table shared with the layer's checks.
using asval::ComponentKind;
using asval::VertexFormatInfo;

// nullptr if the builder cannot decode `format` (the layer reports it; the build is then not classified).
const VertexFormatInfo* FindVertexFormat(VkFormat format);

// All decodable formats, for tests and benchmarks (stable order).
const VertexFormatInfo* VertexFormatsBegin();
const VertexFormatInfo* VertexFormatsEnd();

// Index element size in bytes (0 for VK_INDEX_TYPE_NONE_KHR, -1 for a type the builder does not accept).
int IndexTypeBytes(VkIndexType type);

// Decodes one vertex to floats exactly as the spec's conversion rules say (half is exact; norm formats use
// a correctly rounded division). xyz[2] = 0 for 2-component formats. No NaN test here: see classify.h.
void DecodeVertex(const VertexFormatInfo& info, const void* vertex, float xyz[3]);

}  // namespace asval::builder
