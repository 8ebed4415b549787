// Turning classified geometry into the BVH builder's input: one conservative box per primitive kept.
// "Conservative" means: the box contains the primitive's exact geometry (exactly decoded vertices, exactly
// transformed: products in double are exact, sums are bounded and rounded outward to float), so no
// active primitive's true position can lie outside any box that holds it.
#pragma once

#include <cstdint>
#include <vector>

#include "asval/builder/geometry_view.h"

namespace asval::builder {

// One reference to a primitive: its box and its id (the caller's numbering, see Append*).
// 32 bytes, 16-aligned: the builder loads lo/hi as SIMD vectors (the id rides in lane 3 of lo).
struct alignas(16) PrimRef {
    float lo[3];
    uint32_t id;
    float hi[3];
    uint32_t aux;  // unused by callers; spare
};

struct BuildInput {
    std::vector<PrimRef> refs;
    uint32_t excludedInactive = 0;
    uint32_t excludedDegenerate = 0;   // discarded because ALLOW_UPDATE is not set
    uint32_t excludedSameIndex = 0;    // always discardable
    uint32_t excludedUndefined = 0;    // NaN outside X: behaviour undefined, kept out of the tree (decision)
    uint32_t excludedUnreadable = 0;
    uint32_t excludedInvalid = 0;      // AABB min > max; instance with an unknown reference
    uint32_t infiniteBoxes = 0;        // kept with an unbounded axis (inf coordinates, NaN transform)
    uint32_t degenerateInstances = 0;  // kept as a point at the instance origin
};

// Appends the kept primitives of one geometry; ids are idBase + primitive index within the geometry.
// Degenerate primitives are kept iff allowUpdate (the spec lets a non-updatable build discard them).
void AppendTriangles(const TriangleGeometryView& view, bool allowUpdate, uint32_t idBase, BuildInput* out);
void AppendAabbs(const AabbGeometryView& view, bool allowUpdate, uint32_t idBase, BuildInput* out);

// What the TLAS needs to know about a referenced BLAS.
struct BlasSummary {
    bool known = false;          // false: the reference names no live BLAS (VUID; the instance is excluded)
    uint32_t activePrimitives = 0;
    float lo[3] = {0, 0, 0};     // the BLAS root box (ignored when activePrimitives == 0)
    float hi[3] = {0, 0, 0};
};
using BlasLookup = BlasSummary (*)(uint64_t reference, void* user);

// Instances: box = the exact image of the BLAS box under the instance transform, rounded outward.
// An instance whose BLAS has no active primitive is degenerate: a point at the transform's translation.
void AppendInstances(const InstanceGeometryView& view, BlasLookup lookup, void* user, uint32_t idBase,
                     BuildInput* out);

// Exposed for the property tests: the conservative image of the box [lo, hi] under the row-major 3x4
// matrix m (the VkTransformMatrixKHR layout). Any NaN in a result bound becomes an infinite bound.
void TransformBoxConservative(const float m[12], const float lo[3], const float hi[3], float outLo[3],
                              float outHi[3]);

}  // namespace asval::builder
