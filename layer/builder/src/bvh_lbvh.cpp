// Fast mode: references sorted by the Morton code of their centroids (lbvh_sort.h), then a top-down split
// at the highest differing code bit. Subtrees of <= maxLeafSize references collapse into a leaf when the
// SAH says the leaf is cheaper. Single-threaded (it is several times faster than the SAH path).
#include <algorithm>
#include <cmath>

#include "bvh_code.h"
#include "lbvh_hugepages.h"
#include "lbvh_sort.h"

namespace asval::builder::detail {
namespace {

// The sorted codes the top-down pass reads: 4 bytes each (<= 32 code bits, the default) or 8.
template <class T>
struct Codes {
    const T* codes;
    uint64_t operator[](uint32_t i) const { return codes[i]; }
};

template <class CodeArray>
class LbvhBuilder {
public:
    // `out` has room for every node of the uncollapsed tree (2n - 1); Recorded() says how much was used.
    LbvhBuilder(const PrimRef* refs, CodeArray codes, uint32_t maxLeaf, uint8_t* out, uint32_t* ids)
        : refs_(refs), codes_(codes), maxLeaf_(maxLeaf), begin_(out), cur_(out), ids_(ids) {}

    size_t Recorded() const { return size_t(cur_ - begin_); }

    // Records [b, e) (references in Morton order) as pre-order codes; returns the subtree's SAH cost
    // (unnormalised) and its box. A collapsed subtree's codes are cut back to one leaf code. The recursion
    // reaches every reference once, as a one-reference leaf, in order: that is where its id is copied out.
    // No code at or left of that reference is read afterwards (later ranges start to its right), so `ids`
    // may be the 4-byte code array itself.
    double Build(uint32_t b, uint32_t e, uint32_t depth, __m128* lo, __m128* hi) {
        const uint32_t count = e - b;
        if (count == 1) return Leaf(b, lo, hi);
        uint32_t mid;
        // This recursion goes down to single references. HalvingLevels(count, 1) <= 32 (count < 2^32), so
        // the loop it runs is skipped above the depth where the budget could bind.
        if (depth + 32 >= kMaxDepth && depth + HalvingLevels(count, 1) >= kMaxDepth) {
            mid = b + count / 2;
        } else {
            // Highest bit where the first and last codes differ (the range is sorted, so every code in it
            // shares the bits above).
            const uint64_t diff = codes_[b] ^ codes_[e - 1];
            if (diff == 0) {
                mid = b + count / 2;
            } else {
                // The codes with the bit clear come first; find the last of them. Branch-free: which half
                // the search continues in is random, and mispredicting it was a tenth of the build.
                const uint64_t mask = uint64_t(1) << (63 - __builtin_clzll(diff));
                uint32_t last = b, len = count;  // codes_[b] has the bit clear, codes_[e - 1] has it set
                while (len > 1) {
                    const uint32_t half = len / 2;
                    last += half & (uint32_t((codes_[last + half] & mask) != 0) - 1u);
                    len -= half;
                }
                mid = last + 1;
            }
        }
        uint8_t* const pos = cur_++;
        *pos = kCodeInner;
        __m128 llo, lhi, rlo, rhi;
        // One-reference children are handled here: a call per reference saved (half of all calls).
        const double cl = mid - b == 1 ? Leaf(b, &llo, &lhi) : Build(b, mid, depth + 1, &llo, &lhi);
        const double cr = e - mid == 1 ? Leaf(mid, &rlo, &rhi) : Build(mid, e, depth + 1, &rlo, &rhi);
        *lo = _mm_min_ps(llo, rlo);
        *hi = _mm_min_ps(_mm_set1_ps(INFINITY), _mm_max_ps(lhi, rhi));
        const double area = HalfArea(*lo, *hi);
        const double inner = area + cl + cr;
        if (count <= maxLeaf_ && area * count <= inner) {
            cur_ = pos + 1;  // every descendant was recorded after pos
            *pos = uint8_t(count);
            return area * count;
        }
        return inner;
    }

private:
    // The recursion ends in one-reference leaves only (collapsing makes the larger ones afterwards).
    double Leaf(uint32_t i, __m128* lo, __m128* hi) {
        const __m128 l = _mm_min_ps(_mm_set1_ps(INFINITY), LoadLo(refs_[i]));
        const __m128 h = _mm_max_ps(_mm_set1_ps(-INFINITY), LoadHi(refs_[i]));
        ids_[i] = refs_[i].id;
        *cur_++ = 1;
        *lo = l; *hi = h;
        return HalfArea(l, h);
    }

    const PrimRef* refs_;
    CodeArray codes_;
    uint32_t maxLeaf_;
    uint8_t* begin_;
    uint8_t* cur_;
    uint32_t* ids_;
};

template <class CodeArray>
void Record(const PrimRef* refs, CodeArray codes, uint32_t maxLeaf, Task* tree, uint32_t* ids) {
    const uint32_t n = tree->range.end - tree->range.begin;
    tree->code.resize(size_t(2) * n - 1);  // a binary tree over n references has at most 2n - 1 nodes
    LbvhBuilder<CodeArray> builder(refs, codes, maxLeaf, tree->code.data(), ids);
    builder.Build(tree->range.begin, tree->range.end, 1, &tree->range.lo, &tree->range.hi);
    tree->code.resize(builder.Recorded());
}

}  // namespace

Bvh BuildLbvh(std::vector<PrimRef>& refs, const BuildOptions& options) {
    Bvh bvh;
    const uint32_t n = uint32_t(refs.size());
    if (n == 0) return bvh;
    std::vector<uint32_t> codes;
    std::vector<uint64_t> wideCodes;
    SortByMorton(refs, options.mortonBitsPerAxis, &codes, &wideCodes);
    Task tree;
    tree.range.begin = 0;
    tree.range.end = n;
    tree.range.depth = 1;
    const uint32_t maxLeaf = std::clamp<uint32_t>(options.maxLeafSize, 1, 8);
    if (wideCodes.empty()) {
        // The ids overwrite the codes as the recursion passes them: no second 4-byte array.
        Record(refs.data(), Codes<uint32_t>{codes.data()}, maxLeaf, &tree, codes.data());
        bvh.primIds.swap(codes);
    } else {
        bvh.primIds.resize(n);
        Record(refs.data(), Codes<uint64_t>{wideCodes.data()}, maxLeaf, &tree, bvh.primIds.data());
        std::vector<uint64_t>().swap(wideCodes);
    }
    ReserveHuge(bvh.nodes, CountNodes(tree));
    bvh.nodes.resize(bvh.nodes.capacity());
    ExpandCodes(refs.data(), refs.size(), tree, bvh.nodes.data(), nullptr, &bvh.stats);
    std::vector<PrimRef>().swap(refs);
    return bvh;
}

}  // namespace asval::builder::detail
