#include "bvh_checks.h"

#include <algorithm>
#include <cmath>

namespace bvhcheck {

std::vector<asval::builder::PrimRef> RefsById(const asval::builder::BuildInput& input) {
    uint32_t maxId = 0;
    for (const auto& r : input.refs) maxId = std::max(maxId, r.id + 1);
    std::vector<asval::builder::PrimRef> out(maxId);
    for (auto& r : out) r.aux = kAbsent;
    for (const auto& r : input.refs) { out[r.id] = r; out[r.id].aux = 0; }
    return out;
}

Report CheckTree(const asval::builder::Bvh& bvh, const std::vector<asval::builder::PrimRef>& refsById,
                 uint32_t maxLeaf, bool exactlyOnce) {
    Report r;
    auto fail = [&](const std::string& what) { if (r.violations++ == 0) r.first = what; };
    if (bvh.nodes.empty()) {
        if (!refsById.empty()) fail("empty tree for non-empty input");
        return r;
    }
    const bool checkPrimitives = !refsById.empty();
    std::vector<uint32_t> seen(refsById.size(), 0);
    std::vector<std::pair<uint32_t, uint32_t>> stack = {{0, 1}};
    while (!stack.empty()) {
        const auto [i, depth] = stack.back();
        stack.pop_back();
        if (i >= bvh.nodes.size()) { fail("child index out of range"); continue; }
        const auto& n = bvh.nodes[i];
        r.maxDepth = std::max(r.maxDepth, depth);
        for (int a = 0; a < 3; ++a)
            if (std::isnan(n.lo[a]) || std::isnan(n.hi[a])) fail("NaN in node " + std::to_string(i));
        if (n.count == 0) {
            for (uint32_t c = n.leftOrFirst; c < n.leftOrFirst + 2; ++c) {
                if (c >= bvh.nodes.size()) { fail("child index out of range"); continue; }
                const auto& ch = bvh.nodes[c];
                for (int a = 0; a < 3; ++a)
                    if (!(ch.lo[a] >= n.lo[a] && ch.hi[a] <= n.hi[a])) fail("child outside parent at node " + std::to_string(i));
                stack.push_back({c, depth + 1});
            }
        } else {
            r.maxLeaf = std::max(r.maxLeaf, n.count);
            if (n.leftOrFirst + uint64_t(n.count) > bvh.primIds.size()) { fail("leaf range"); continue; }
            for (uint32_t k = 0; k < n.count && checkPrimitives; ++k) {
                const uint32_t id = bvh.primIds[n.leftOrFirst + k];
                if (id >= refsById.size() || refsById[id].aux == kAbsent) { fail("unknown id"); continue; }
                ++seen[id];
                const auto& p = refsById[id];
                for (int a = 0; a < 3; ++a)
                    if (!(p.lo[a] >= n.lo[a] && p.hi[a] <= n.hi[a])) fail("primitive box outside leaf, id " + std::to_string(id));
            }
        }
    }
    if (r.maxLeaf > maxLeaf) fail("leaf too large: " + std::to_string(r.maxLeaf));
    if (r.maxDepth > 64) fail("too deep: " + std::to_string(r.maxDepth));
    if (exactlyOnce)
        for (size_t id = 0; id < seen.size(); ++id)
            if (refsById[id].aux != kAbsent && seen[id] != 1) { fail("id " + std::to_string(id) + " referenced " + std::to_string(seen[id]) + " times"); break; }
    return r;
}

}  // namespace bvhcheck
