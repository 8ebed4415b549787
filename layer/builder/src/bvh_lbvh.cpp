// Fast mode: Morton codes of the centroids, an LSD radix sort (stable, so deterministic), then a
// top-down split at the highest differing code bit. Subtrees of <= maxLeafSize references collapse into a
// leaf when the SAH says the leaf is cheaper. Single-threaded (it is several times faster than the SAH path).
#include <algorithm>
#include <cmath>

#include "bvh_code.h"

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
    LbvhBuilder(const PrimRef* refs, const uint64_t* codes, uint32_t maxLeaf, std::vector<uint8_t>* out)
        : refs_(refs), codes_(codes), maxLeaf_(maxLeaf), out_(out) {}

    // Records [b, e) (references in Morton order) as pre-order codes; returns the subtree's SAH cost
    // (unnormalised) and its box. A collapsed subtree's codes are cut back to one leaf code.
    double Build(uint32_t b, uint32_t e, uint32_t depth, int bit, __m128* lo, __m128* hi) {
        const uint32_t count = e - b;
        if (count == 1) return Leaf(b, e, lo, hi);
        uint32_t mid;
        // This recursion goes down to single references. HalvingLevels(count, 1) <= 32 (count < 2^32), so
        // the loop it runs is skipped above the depth where the budget could bind.
        if (depth + 32 >= kMaxDepth && depth + HalvingLevels(count, 1) >= kMaxDepth) {
            mid = b + count / 2;
        } else {
            // Highest bit (at or below `bit`) where the first and last codes differ.
            const uint64_t diff = codes_[b] ^ codes_[e - 1];
            if (diff == 0) {
                mid = b + count / 2;
            } else {
                bit = 63 - __builtin_clzll(diff);
                const uint64_t mask = uint64_t(1) << bit;
                uint32_t l = b, h = e - 1;  // first index with the bit set is in (l, h]
                while (h - l > 1) {
                    const uint32_t m = l + (h - l) / 2;
                    if (codes_[m] & mask) h = m; else l = m;
                }
                mid = h;
                bit -= 1;
            }
        }
        const size_t pos = out_->size();
        out_->push_back(kCodeInner);
        __m128 llo, lhi, rlo, rhi;
        const double cl = Build(b, mid, depth + 1, bit, &llo, &lhi);
        const double cr = Build(mid, e, depth + 1, bit, &rlo, &rhi);
        *lo = _mm_min_ps(llo, rlo);
        *hi = _mm_min_ps(_mm_set1_ps(INFINITY), _mm_max_ps(lhi, rhi));
        const double area = HalfArea(*lo, *hi);
        const double inner = area + cl + cr;
        if (count <= maxLeaf_ && area * count <= inner) {
            out_->resize(pos + 1);  // every descendant was recorded after pos
            (*out_)[pos] = uint8_t(count);
            return area * count;
        }
        return inner;
    }

private:
    double Leaf(uint32_t b, uint32_t e, __m128* lo, __m128* hi) {
        __m128 l = _mm_set1_ps(INFINITY), h = _mm_set1_ps(-INFINITY);
        for (uint32_t i = b; i < e; ++i) {
            l = _mm_min_ps(l, LoadLo(refs_[i]));
            h = _mm_max_ps(h, LoadHi(refs_[i]));
        }
        out_->push_back(uint8_t(e - b));
        *lo = l; *hi = h;
        return HalfArea(l, h) * (e - b);
    }

    const PrimRef* refs_;
    const uint64_t* codes_;
    uint32_t maxLeaf_;
    std::vector<uint8_t>* out_;
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

    auto mortonCode = [&](const PrimRef& r) {
        alignas(16) float c[4];
        _mm_store_ps(c, Centroid(r));
        uint64_t code = 0;
        for (int a = 0; a < 3; ++a) {
            double q = (double(c[a]) - double(lo[a])) * scale[a];
            q = q >= 0 ? (q > cells ? cells : q) : 0;  // NaN (from an infinite box) -> 0
            code |= Spread3(uint64_t(q)) << (2 - a);
        }
        return code;
    };
    // LSD radix sort over the 3 * bitsPerAxis code bits. Stable: ties keep input order, so both paths give
    // the same permutation.
    const uint32_t codeBits = 3 * bitsPerAxis;
    std::vector<uint64_t> codes;  // the top-down pass needs only the codes, in sorted reference order
    if (codeBits <= 32) {
        // Common case (default 30 bits): sort 8-byte keys `code << 32 | index` on the code bits, with the
        // histograms of every digit counted in one pass.
        // Three digits of ceil(bits / 3) <= 11 bits (10 by default: fewer scatter streams than 11).
        constexpr uint32_t kDigits = 3;
        const uint32_t digitBits = (codeBits + kDigits - 1) / kDigits, buckets = 1u << digitBits, mask = buckets - 1;
        std::vector<uint64_t> keys(n), tmp(n);
        std::vector<uint32_t> hist(kDigits * buckets, 0);
        for (uint32_t i = 0; i < n; ++i) {
            const uint64_t code = mortonCode(refs[i]);
            keys[i] = code << 32 | i;
            for (uint32_t d = 0; d < kDigits; ++d) ++hist[d * buckets + ((code >> (digitBits * d)) & mask)];
        }
        for (uint32_t d = 0; d < kDigits && digitBits * d < codeBits; ++d) {
            uint32_t* h = &hist[d * buckets];
            uint32_t sum = 0;
            for (uint32_t k = 0; k < buckets; ++k) { const uint32_t c = h[k]; h[k] = sum; sum += c; }
            const unsigned shift = 32 + digitBits * d;
            for (const uint64_t k : keys) tmp[h[(k >> shift) & mask]++] = k;
            keys.swap(tmp);
        }
        std::vector<uint64_t>().swap(tmp);
        // Gather the references into Morton order: the top-down pass then reads them sequentially.
        {
            std::vector<PrimRef> sortedRefs(n);
            for (uint32_t i = 0; i < n; ++i) sortedRefs[i] = refs[uint32_t(keys[i])];
            refs.swap(sortedRefs);
        }
        for (uint64_t& k : keys) k >>= 32;
        codes.swap(keys);
    } else {
        // More than 32 code bits: 16-byte keys, 11-bit digits.
        std::vector<Keyed> keys(n), tmp(n);
        for (uint32_t i = 0; i < n; ++i) keys[i] = {mortonCode(refs[i]), i, 0};
        for (uint32_t shift = 0; shift < codeBits; shift += 11) {
            uint32_t hist[2048] = {};
            for (const Keyed& k : keys) ++hist[(k.code >> shift) & 2047];
            uint32_t sum = 0;
            for (uint32_t& h : hist) { const uint32_t c = h; h = sum; sum += c; }
            for (const Keyed& k : keys) tmp[hist[(k.code >> shift) & 2047]++] = k;
            keys.swap(tmp);
        }
        std::vector<Keyed>().swap(tmp);
        {
            std::vector<PrimRef> sortedRefs(n);
            for (uint32_t i = 0; i < n; ++i) sortedRefs[i] = refs[keys[i].ref];
            refs.swap(sortedRefs);
        }
        codes.resize(n);
        for (uint32_t i = 0; i < n; ++i) codes[i] = keys[i].code;
    }
    Task tree;
    tree.range.begin = 0;
    tree.range.end = n;
    tree.range.depth = 1;
    tree.code.reserve(size_t(2) * n - 1);  // a binary tree over n references has at most 2n - 1 nodes
    LbvhBuilder builder(refs.data(), codes.data(), std::clamp<uint32_t>(options.maxLeafSize, 1, 8), &tree.code);
    builder.Build(0, n, 1, 63, &tree.range.lo, &tree.range.hi);
    std::vector<uint64_t>().swap(codes);
    bvh.nodes.resize(CountNodes(tree));
    ExpandCodes(refs.data(), tree, bvh.nodes.data(), &bvh.stats);
    bvh.primIds.resize(n);
    for (uint32_t i = 0; i < n; ++i) bvh.primIds[i] = refs[i].id;
    std::vector<PrimRef>().swap(refs);
    return bvh;
}

}  // namespace asval::builder::detail
