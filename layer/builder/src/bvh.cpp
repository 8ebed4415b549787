// Entry point: mode dispatch, statistics and the SAH metric.
#include <algorithm>
#include <utility>

#include "bvh_internal.h"

namespace asval::builder {
namespace detail {

void FillStats(Bvh& bvh) {
    BuildStats& s = bvh.stats;
    s.references = uint32_t(bvh.primIds.size());
    if (bvh.nodes.empty()) return;
    std::vector<std::pair<uint32_t, uint32_t>> stack = {{0, 1}};  // (node, depth)
    while (!stack.empty()) {
        const auto [i, depth] = stack.back();
        stack.pop_back();
        const BvhNode& n = bvh.nodes[i];
        s.maxDepth = std::max(s.maxDepth, depth);
        if (n.count != 0) {
            ++s.leaves;
            s.maxLeafSize = std::max(s.maxLeafSize, n.count);
        } else {
            stack.push_back({n.leftOrFirst, depth + 1});
            stack.push_back({n.leftOrFirst + 1, depth + 1});
        }
    }
}

}  // namespace detail

Bvh BuildBvh(BuildInput&& input, const BuildOptions& options) {
    std::vector<PrimRef> refs = std::move(input.refs);
    Bvh bvh = options.mode == BuildMode::Lbvh ? detail::BuildLbvh(refs, options)
                                              : detail::BuildBinnedSah(refs, options);
    detail::FillStats(bvh);
    return bvh;
}

double SahCost(const Bvh& bvh) {
    if (bvh.nodes.empty()) return 0.0;
    auto area = [](const BvhNode& n) { return detail::HalfArea(_mm_loadu_ps(n.lo), _mm_loadu_ps(n.hi)); };
    double sum = 0.0;
    for (const BvhNode& n : bvh.nodes) sum += area(n) * (n.count == 0 ? 1.0 : double(n.count));
    const double root = area(bvh.nodes[0]);
    return root > 0 ? sum / root : 0.0;
}

}  // namespace asval::builder
