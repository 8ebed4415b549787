// The reference BVH: binary, leaves of at most maxLeafSize references, depth at most 64, boxes that
// contain every referenced primitive box (and so, through build_input.h, every exact primitive).
// Output is identical across runs and for any thread count.
#pragma once

#include <cstdint>
#include <vector>

#include "asval/builder/build_input.h"

namespace asval::builder {

struct BvhNode {
    // Left uninitialised on purpose: the builders size the output before writing it front to back, and a
    // zero-filled vector would make every page resident at once (see docs/builder.md, "Memory").
    BvhNode() {}  // NOLINT(modernize-use-equals-default): `= default` would zero-fill in value-initialisation
    float lo[3];
    uint32_t leftOrFirst;  // inner: index of the left child (the right one follows); leaf: first reference
    float hi[3];
    uint32_t count;        // 0: inner node; otherwise the leaf's reference count
};

enum class BuildMode : uint8_t {
    BinnedSah,  // default: binned SAH, SAH-terminated leaves
    Lbvh,       // fast: Morton codes + radix sort + highest-differing-bit splits, SAH leaf collapse
};

enum class SpatialSplits : uint8_t { Off, Auto, On };

struct BuildOptions {
    BuildMode mode = BuildMode::BinnedSah;
    uint32_t bins = 16;          // binned SAH: bins per axis (4..64)
    uint32_t maxLeafSize = 8;    // 1..8
    uint32_t mortonBitsPerAxis = 10;  // LBVH: 8..21
    SpatialSplits spatialSplits = SpatialSplits::Auto;
    float splitBudget = 0.4f;    // extra references allowed by pre-splitting, as a fraction of the input
    float splitFactor = 0.5f;    // once splitting is needed (Auto: largest box > 16x the mean box area),
                                 // references whose box area exceeds splitFactor x the mean are cut
    uint32_t threads = 1;        // 1 or more; the output does not depend on it
};

struct BuildStats {
    uint32_t references = 0;     // after splitting
    uint32_t splitReferences = 0;
    uint32_t maxDepth = 0;
    uint32_t maxLeafSize = 0;
    uint32_t leaves = 0;
    bool usedSpatialSplits = false;
};

struct Bvh {
    std::vector<BvhNode> nodes;       // nodes[0] is the root; empty for an empty input
    std::vector<uint32_t> primIds;    // leaves index this; values are PrimRef::id (may repeat after splits)
    BuildStats stats;
};

// Builds from `input.refs` (consumed). Triangle pre-splitting needs the geometry, so it is applied by
// BuildTriangleBvh (bvh_triangles.h); BuildBvh itself never splits.
Bvh BuildBvh(BuildInput&& input, const BuildOptions& options);

// The anchors document's metric: [sum_inner A(n) + sum_leaf count * A(leaf)] / A(root), C_t = C_i = 1,
// areas in double with coordinates clamped to +-FLT_MAX (an infinite box has a finite, huge area).
double SahCost(const Bvh& bvh);

}  // namespace asval::builder
