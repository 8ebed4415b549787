// One-call triangle BLAS build: classify + conservative boxes + (automatic) spatial pre-splitting + BVH.
#pragma once

#include <cstddef>

#include "asval/builder/bvh.h"

namespace asval::builder {

// Geometry g's primitive i gets id idBase(g) + i, where idBase(g) = sum of the earlier primitiveCounts.
Bvh BuildTriangleBvh(const TriangleGeometryView* geometries, size_t geometryCount, bool allowUpdate,
                     const BuildOptions& options, BuildInput* excludedCounts = nullptr);

// Spatial pre-splitting ("early split clipping"): references whose box is far larger than the average
// (the long slivers of a "teapot in a stadium" scene) are cut at spatial midpoints into several
// references, each bounding only its part of the triangle (clipped in double, widened by a margin that
// covers the rounding, intersected with the original box: still conservative). With Auto, nothing is
// split unless such references exist. Returns the number of references added.
uint32_t SplitLargeTriangles(const TriangleGeometryView* geometries, size_t geometryCount,
                             const BuildOptions& options, BuildInput* input);

}  // namespace asval::builder
