// Fast mode: Morton codes of the centroids, an LSD radix sort (stable, so deterministic), then a
// top-down split at the highest differing code bit. Subtrees of <= maxLeafSize references collapse into a
// leaf when the SAH says the leaf is cheaper. Single-threaded (it is several times faster than the SAH path).
#include <algorithm>
#include <cmath>

#include "bvh_internal.h"

namespace asval::builder::detail {
namespace {

// Spreads the low 21 bits of x so that bit i lands on bit 3i.
uint64_t Spread3(uint64_t x) {
    x &= 0x1FFFFFull;
    x = (x | x << 32) & 0x1F00000000FFFFull;
    x = (x | x << 16) & 0x1F0000FF0000FFull;
    x = (x | x << 8) & 0x100F00F00F00F00Full;
    x = (x | x << 4) & 0x10C30C30C30C30C3ull;
    x = (x | x << 2) & 0x1249249249249249ull;
    return x;
}

struct Keyed {
    uint64_t code;
    uint32_t ref;
    uint32_t pad;
};

class LbvhBuilder {
public:
    LbvhBuilder(const std::vector<PrimRef>& refs, const std::vector<Keyed>& sorted, uint32_t maxLeaf, Bvh* out)
        : refs_(refs), sorted_(sorted), maxLeaf_(maxLeaf), out_(out) {}

    // Builds [b, e) into out_->nodes[slot]; returns the subtree's SAH cost (unnormalised).
    double Build(uint32_t slot, uint32_t b, uint32_t e, uint32_t depth, int bit) {
        const uint32_t count = e - b;
        if (count == 1) return Leaf(slot, b, e);
        uint32_t mid;
        if (depth + HalvingLevels(count, 1) >= kMaxDepth) {  // this recursion goes down to single references
            mid = b + count / 2;
        } else {
            // Highest bit (at or below `bit`) where the first and last codes differ.
            const uint64_t diff = sorted_[b].code ^ sorted_[e - 1].code;
            if (diff == 0) {
                mid = b + count / 2;
            } else {
                bit = 63 - __builtin_clzll(diff);
                const uint64_t mask = uint64_t(1) << bit;
                uint32_t lo = b, hi = e - 1;  // first index with the bit set is in (lo, hi]
                while (hi - lo > 1) {
                    const uint32_t m = lo + (hi - lo) / 2;
                    if (sorted_[m].code & mask) hi = m; else lo = m;
                }
                mid = hi;
                bit -= 1;
            }
        }
        const uint32_t childSlot = uint32_t(out_->nodes.size());
        out_->nodes.emplace_back();
        out_->nodes.emplace_back();
        const double cl = Build(childSlot, b, mid, depth + 1, bit);
        const double cr = Build(childSlot + 1, mid, e, depth + 1, bit);
        const BvhNode& l = out_->nodes[childSlot];
        const BvhNode& r = out_->nodes[childSlot + 1];
        const __m128 lo = _mm_min_ps(_mm_loadu_ps(l.lo), _mm_loadu_ps(r.lo));
        const __m128 hi = _mm_min_ps(_mm_set1_ps(INFINITY), _mm_max_ps(_mm_loadu_ps(l.hi), _mm_loadu_ps(r.hi)));
        const double area = HalfArea(lo, hi);
        BvhNode& n = out_->nodes[slot];
        StoreNodeBox(n, lo, hi);
        const double inner = area + cl + cr;
        if (count <= maxLeaf_ && area * count <= inner) {
            out_->nodes.resize(childSlot);  // every descendant was appended after childSlot
            n.leftOrFirst = b;
            n.count = count;
            return area * count;
        }
        n.leftOrFirst = childSlot;
        n.count = 0;
        return inner;
    }

private:
    double Leaf(uint32_t slot, uint32_t b, uint32_t e) {
        __m128 lo = _mm_set1_ps(INFINITY), hi = _mm_set1_ps(-INFINITY);
        for (uint32_t i = b; i < e; ++i) {
            lo = _mm_min_ps(lo, LoadLo(refs_[sorted_[i].ref]));
            hi = _mm_max_ps(hi, LoadHi(refs_[sorted_[i].ref]));
        }
        BvhNode& n = out_->nodes[slot];
        StoreNodeBox(n, lo, hi);
        n.leftOrFirst = b;
        n.count = e - b;
        return HalfArea(lo, hi) * (e - b);
    }

    const std::vector<PrimRef>& refs_;
    const std::vector<Keyed>& sorted_;
    uint32_t maxLeaf_;
    Bvh* out_;
};

}  // namespace

Bvh BuildLbvh(std::vector<PrimRef>& refs, const BuildOptions& options) {
    Bvh bvh;
    const uint32_t n = uint32_t(refs.size());
    if (n == 0) return bvh;
    const uint32_t bitsPerAxis = std::clamp<uint32_t>(options.mortonBitsPerAxis, 1, 21);

    __m128 clo = _mm_set1_ps(INFINITY), chi = _mm_set1_ps(-INFINITY);
    for (const PrimRef& r : refs) {
        const __m128 c = Centroid(r);
        clo = _mm_min_ps(clo, c);
        chi = _mm_max_ps(chi, c);
    }
    alignas(16) float lo[4], hi[4];
    _mm_store_ps(lo, clo);
    _mm_store_ps(hi, chi);
    double scale[3];
    const double cells = double((uint64_t(1) << bitsPerAxis) - 1);
    for (int a = 0; a < 3; ++a) {
        const double extent = double(hi[a]) - double(lo[a]);
        scale[a] = extent > 0 ? cells / extent : 0.0;
    }

    std::vector<Keyed> keys(n), tmp(n);
    for (uint32_t i = 0; i < n; ++i) {
        alignas(16) float c[4];
        _mm_store_ps(c, Centroid(refs[i]));
        uint64_t code = 0;
        for (int a = 0; a < 3; ++a) {
            double q = (double(c[a]) - double(lo[a])) * scale[a];
            q = q >= 0 ? (q > cells ? cells : q) : 0;  // NaN (from an infinite box) -> 0
            code |= Spread3(uint64_t(q)) << (2 - a);
        }
        keys[i] = {code, i, 0};
    }
    // LSD radix sort, 11-bit digits over the 3 * bitsPerAxis code bits. Stable: ties keep input order.
    const uint32_t codeBits = 3 * bitsPerAxis;
    for (uint32_t shift = 0; shift < codeBits; shift += 11) {
        uint32_t hist[2048] = {};
        for (const Keyed& k : keys) ++hist[(k.code >> shift) & 2047];
        uint32_t sum = 0;
        for (uint32_t& h : hist) { const uint32_t c = h; h = sum; sum += c; }
        for (const Keyed& k : keys) tmp[hist[(k.code >> shift) & 2047]++] = k;
        keys.swap(tmp);
    }
    std::vector<Keyed>().swap(tmp);

    // Gather the references into Morton order: the top-down pass then reads them sequentially.
    {
        std::vector<PrimRef> sortedRefs(n);
        for (uint32_t i = 0; i < n; ++i) sortedRefs[i] = refs[keys[i].ref];
        refs.swap(sortedRefs);
    }
    for (uint32_t i = 0; i < n; ++i) keys[i].ref = i;
    // A binary tree over n references has at most 2n - 1 nodes: reserving that avoids regrowth copies
    // (the dominant term of the peak); the unused tail is returned below only when it is large.
    bvh.nodes.reserve(size_t(2) * n - 1);
    bvh.nodes.emplace_back();
    LbvhBuilder builder(refs, keys, std::clamp<uint32_t>(options.maxLeafSize, 1, 8), &bvh);
    builder.Build(0, 0, n, 1, 63);
    std::vector<Keyed>().swap(keys);
    bvh.primIds.resize(n);
    for (uint32_t i = 0; i < n; ++i) bvh.primIds[i] = refs[i].id;
    std::vector<PrimRef>().swap(refs);
    if (bvh.nodes.size() < bvh.nodes.capacity() / 2) bvh.nodes.shrink_to_fit();
    return bvh;
}

}  // namespace asval::builder::detail
