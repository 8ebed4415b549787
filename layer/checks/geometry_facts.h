#pragma once
// What the per-geometry rules of every build family read of one geometry, looked up once per geometry: the
// geometry, its row of the shared vertex-format table, the device's buffer features of its vertex format and its
// index size (triangles). The geometry pass (geometry_pass.h) reads them once for all families; a family's own
// walk reads them for the infos it walks. A reader keeps the last vertex format it looked up: the geometries of
// one build nearly always share one format, whose row and features are then looked up once per walk.
#include <vulkan/vulkan.h>

#include <optional>

#include "asval/vertex_formats.h"
#include "device_state.h"
#include "vertex_format_alignment.h"

namespace asval {

struct GeometryFacts {
  const VkAccelerationStructureGeometryKHR& geometry;
  // Triangles: vertexFormat's facts (an all-zero row for a format the table does not describe); other types:
  // the all-zero row of VK_FORMAT_UNDEFINED, which no rule of theirs reads.
  const VertexFormatInfo& format;
  // Triangles: VkFormatProperties::bufferFeatures of vertexFormat (nullopt: the layer cannot ask); other types:
  // nullopt, which no rule of theirs reads. The reader's own copy (no per-geometry copy of it).
  const std::optional<VkFormatFeatureFlags>& features;
  int index_size;  // triangles: IndexTypeSize(indexType); other types: 0
};

class GeometryFactsReader {
 public:
  static constexpr std::optional<VkFormatFeatureFlags> kNoFeatures{};

  explicit GeometryFactsReader(const DeviceState& state) : state_(state) {}

  [[gnu::always_inline]] GeometryFacts Read(const VkAccelerationStructureGeometryKHR& g) {
    if (g.geometryType != VK_GEOMETRY_TYPE_TRIANGLES_KHR) {
      return GeometryFacts{g, VertexFormatFacts(VK_FORMAT_UNDEFINED), kNoFeatures, 0};
    }
    const VkAccelerationStructureGeometryTrianglesDataKHR& tri = g.geometry.triangles;
    // row_ is null until a first lookup, and an app may pass VK_FORMAT_MAX_ENUM, the value format_ starts at.
    if (tri.vertexFormat != format_ || !row_) {
      format_ = tri.vertexFormat;
      row_ = &VertexFormatFacts(format_);
      features_ = state_.format_features.BufferFeatures(format_);
    }
    return GeometryFacts{g, *row_, features_, IndexTypeSize(tri.indexType)};
  }

 private:
  const DeviceState& state_;
  VkFormat format_ = VK_FORMAT_MAX_ENUM;  // the last triangle format looked up (none yet)
  const VertexFormatInfo* row_ = nullptr;
  std::optional<VkFormatFeatureFlags> features_;
};

}  // namespace asval
