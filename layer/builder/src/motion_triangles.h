// Private: classification of VK_NV_ray_tracing_motion_blur triangles (vertex data at time 0 and time 1).
#pragma once

#include "asval/builder/classify.h"

namespace asval::builder::detail {

// ClassifyTriangles for a view with motionVertexData set (see classify.h for the rules).
ClassifyResult ClassifyMotionTriangles(const TriangleGeometryView& view, ActivityRecord* record, uint8_t* states);

// Byte offset of vertex k (0..2) of triangle t from the start of vertexData (the same for both times).
// Only for triangles the classifier found readable.
uint64_t MotionVertexOffset(const TriangleGeometryView& view, int indexBytes, uint32_t t, int k);

}  // namespace asval::builder::detail
