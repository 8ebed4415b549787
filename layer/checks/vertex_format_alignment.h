#pragma once
// The alignment a vertex format imposes on acceleration-structure build inputs: the size of the format if it
// is a packed format, else its component size (the smallest component, in bytes). Read by the rules on
// vertexData (pInfos-03711), vertexStride (03735) and primitiveOffset of non-indexed triangles (03657), once
// per triangle geometry each: an index into the shared vertex-format table (asval/vertex_formats.h) for the
// core formats.
#include <vulkan/vulkan.h>

#include <cstdint>

#include "asval/vertex_formats.h"

namespace asval {

struct VertexFormatAlignment {
  // A power of two (1, 2, 4 or 8), so the rules test multiples with a mask; 0: a format this table does not
  // describe (depth, compressed, multi-planar, newer than the headers).
  uint32_t bytes = 0;
  bool packed = false;  // true: bytes is the packed size of the whole texel

  // What `bytes` is, for messages: "... is not a multiple of 4 bytes, the component size of ...".
  const char* What() const { return packed ? "size of the packed format" : "component size"; }
};

inline VertexFormatAlignment AlignmentOfVertexFormat(VkFormat format) {
  const VertexFormatInfo& facts = VertexFormatFacts(format);
  return {facts.componentBytes, facts.packed};
}

// Bytes of one index of `type`: 2, 4, 1 (UINT8), 0 for VK_INDEX_TYPE_NONE_KHR, -1 for a value the headers
// do not name.
inline int IndexTypeSize(VkIndexType type) {
  switch (type) {
    case VK_INDEX_TYPE_NONE_KHR:
      return 0;
    case VK_INDEX_TYPE_UINT16:
      return 2;
    case VK_INDEX_TYPE_UINT32:
      return 4;
    case VK_INDEX_TYPE_UINT8_EXT:
      return 1;
    default:
      return -1;
  }
}

}  // namespace asval
