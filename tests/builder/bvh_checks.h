// Structural and containment checks shared by the BVH tests.
#pragma once

#include <string>
#include <vector>

#include "asval/builder/bvh.h"

namespace bvhcheck {

constexpr uint32_t kAbsent = 0xFFFFFFFFu;  // PrimRef::aux of ids that were not kept

// refs indexed by id; ids missing from `input` get aux = kAbsent.
std::vector<asval::builder::PrimRef> RefsById(const asval::builder::BuildInput& input);

struct Report {
    uint64_t violations = 0;  // any failed property
    std::string first;
    uint32_t maxDepth = 0;
    uint32_t maxLeaf = 0;
};

// Every node box free of NaN; every child box inside its parent; leaves <= maxLeaf; depth <= 64; every id
// of `refsById` referenced exactly once (when `exactlyOnce`) and inside its leaf's box. An empty
// `refsById` checks the structure only (used after spatial splits, where pieces are smaller than the box).
Report CheckTree(const asval::builder::Bvh& bvh, const std::vector<asval::builder::PrimRef>& refsById,
                 uint32_t maxLeaf, bool exactlyOnce);

// For each leaf reference: visits (leaf box, id).
template <typename Fn>
void ForEachLeafRef(const asval::builder::Bvh& bvh, Fn&& fn) {
    for (const auto& n : bvh.nodes)
        if (n.count != 0)
            for (uint32_t k = 0; k < n.count; ++k) fn(n, bvh.primIds[n.leftOrFirst + k]);
}

}  // namespace bvhcheck
