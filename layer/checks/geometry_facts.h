#pragma once
// What the per-geometry rules of every build family read of one geometry, looked up once per geometry: the
// geometry, its row of the shared vertex-format table and its index size (triangles). The geometry pass
// (geometry_pass.h) computes it once for all families; a family's own walk computes it for the infos it walks.
#include <vulkan/vulkan.h>

#include "asval/vertex_formats.h"
#include "vertex_format_alignment.h"

namespace asval {

struct GeometryFacts {
  const VkAccelerationStructureGeometryKHR& geometry;
  // Triangles: vertexFormat's facts (an all-zero row for a format the table does not describe); other types:
  // the all-zero row of VK_FORMAT_UNDEFINED, which no rule of theirs reads.
  const VertexFormatInfo& format;
  int index_size;  // triangles: IndexTypeSize(indexType); other types: 0
};

[[gnu::always_inline]] inline GeometryFacts FactsOf(const VkAccelerationStructureGeometryKHR& g) {
  if (g.geometryType == VK_GEOMETRY_TYPE_TRIANGLES_KHR) {
    const VkAccelerationStructureGeometryTrianglesDataKHR& tri = g.geometry.triangles;
    return GeometryFacts{g, VertexFormatFacts(tri.vertexFormat), IndexTypeSize(tri.indexType)};
  }
  return GeometryFacts{g, VertexFormatFacts(VK_FORMAT_UNDEFINED), 0};
}

}  // namespace asval
