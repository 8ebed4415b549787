// Entry point: mode dispatch and the SAH metric.
#include <algorithm>
#include <utility>

#include "bvh_internal.h"
#include "float_mode.h"

namespace asval::builder {

Bvh BuildBvh(BuildInput&& input, const BuildOptions& options) {
    const detail::FloatModeGuard mode;
    std::vector<PrimRef> refs = std::move(input.refs);
    Bvh bvh = options.mode == BuildMode::Lbvh ? detail::BuildLbvh(refs, options)
                                              : detail::BuildBinnedSah(refs, options);
    bvh.stats.references = uint32_t(bvh.primIds.size());  // the rest was counted while expanding
    return bvh;
}

double SahCost(const Bvh& bvh) {
    const detail::FloatModeGuard mode;
    if (bvh.nodes.empty()) return 0.0;
    auto area = [](const BvhNode& n) { return detail::HalfArea(_mm_loadu_ps(n.lo), _mm_loadu_ps(n.hi)); };
    double sum = 0.0;
    for (const BvhNode& n : bvh.nodes) sum += area(n) * (n.count == 0 ? 1.0 : double(n.count));
    const double root = area(bvh.nodes[0]);
    return root > 0 ? sum / root : 0.0;
}

}  // namespace asval::builder
