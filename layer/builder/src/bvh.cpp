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
    // Both builders place children after their parent, so one forward pass propagates depths.
    std::vector<uint8_t> depth(bvh.nodes.size(), 0);
    depth[0] = 1;
    for (size_t i = 0; i < bvh.nodes.size(); ++i) {
        const BvhNode& n = bvh.nodes[i];
        s.maxDepth = std::max<uint32_t>(s.maxDepth, depth[i]);
        if (n.count != 0) {
            ++s.leaves;
            s.maxLeafSize = std::max(s.maxLeafSize, n.count);
        } else {
            depth[n.leftOrFirst] = depth[n.leftOrFirst + 1] = uint8_t(depth[i] + 1);
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
