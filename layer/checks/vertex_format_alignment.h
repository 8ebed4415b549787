#pragma once
// The alignment a vertex format imposes on acceleration-structure build inputs: the size of the format if it
// is a packed format, else its component size (the smallest component, in bytes). Read by the rules on
// vertexData (pInfos-03711), vertexStride (03735) and primitiveOffset of non-indexed triangles (03657).
#include <vulkan/vulkan.h>

#include <cstdint>

namespace asval {

struct VertexFormatAlignment {
  uint32_t bytes = 0;   // 0: a format this table does not describe (depth, compressed, multi-planar, newer)
  bool packed = false;  // true: bytes is the packed size of the whole texel
};

VertexFormatAlignment AlignmentOfVertexFormat(VkFormat format);

// Bytes of one index of `type`: 2, 4, 1 (UINT8), 0 for VK_INDEX_TYPE_NONE_KHR, -1 for a value the headers
// do not name.
int IndexTypeSize(VkIndexType type);

}  // namespace asval
