// Binned SAH builder (default mode). Top-down; a node's references are binned by centroid on all three
// axes (bvh_bins.h), the bins are swept for the cheapest SAH split, and the references are partitioned.
//
// Binning and partitioning are one pass per level, not two: while a node's references are partitioned,
// each is binned into its child's bins on a grid inherited from the parent (the split axis cut at the
// split plane, the other axes unchanged). A child whose occupied bins span less than kLooseGrid of that
// grid on some axis (with 16 bins: all its centroids in one bin) is binned again on its own grid before it
// is split, so no axis is left without a split candidate. Re-binning more eagerly (at a span below half
// the grid) bought 0.04-0.1% SAH on the mesh scenes for 10-15% of the build time. Small nodes take an
// exact split (bvh_small_splits.h).
//
// Nodes up to kScratchRefs references are partitioned out of place, into a per-thread scratch of at most
// 1/8 of the references (it stays in cache, and peak memory grows by a few bytes per primitive at most);
// larger ones in place. The root's box and bins are computed in fixed chunks that idle threads help with
// (merging chunks is exact, so the result does not depend on the thread count).
//
// Subtrees above kSpawnRefs become tasks that any thread may run; each task records its subtree as a
// pre-order byte code (1 byte per node, no boxes), expanded into the output once, after the build
// (bvh_code.h), so the tree is identical for every thread count.
#include <emmintrin.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <thread>

#include "bvh_bins.h"
#include "bvh_code.h"
#include "bvh_small_splits.h"
#include "bvh_task_queue.h"
#include "float_mode.h"

namespace asval::builder::detail {
namespace {

constexpr uint32_t kSpawnRefs = 4096;
constexpr float kLooseGrid = 0.125f;     // see the file comment
constexpr uint32_t kSideSample = 32;      // references sampled to choose the partition loop
constexpr uint32_t kScratchRefs = 1u << 16;
constexpr uint32_t kScratchMinRefs = 1u << 10;
constexpr uint32_t kChunkRefs = 1u << 16;  // chunk of the parallel passes over large nodes
constexpr uint32_t kChunkedMin = 4 * kChunkRefs;

// Per-thread bin storage: the bins of the two children of the node at depth d live in slot (d + 1, side),
// so a node's bins survive while its left subtree is built (which only uses deeper slots).
class Workspace {
public:
    explicit Workspace(uint32_t bins) : bins_(bins) {}
    PrimRef* Scratch(uint32_t count) {
        if (scratch_.size() < count) scratch_.resize(std::max<size_t>(count, 2 * scratch_.size()));
        return scratch_.data();
    }
    BinSet* Slot(uint32_t depth, int side) {
        const size_t i = size_t(depth) * 2 + size_t(side);
        while (slots_.size() <= i) slots_.push_back(std::make_unique<BinSet>(bins_));
        return slots_[i].get();
    }

private:
    uint32_t bins_;
    std::vector<std::unique_ptr<BinSet>> slots_;
    std::vector<PrimRef> scratch_;
};

// A split chosen from a node's bins.
struct BinSplit {
    int axis = -1;
    uint32_t bin = 0;       // references with bin < this go left
    uint32_t leftCount = 0;
    double cost = INFINITY;
};

uint32_t Chunks(uint32_t count) { return (count + kChunkRefs - 1) / kChunkRefs; }

class BinnedBuilder {
public:
    BinnedBuilder(PrimRef* refs, uint32_t totalRefs, const BuildOptions& o, TaskQueue* q)
        : refs_(refs), bins_(std::clamp<uint32_t>(o.bins, 2, kMaxBins)),
          maxLeaf_(std::clamp<uint32_t>(o.maxLeafSize, 1, 8)),
          scratchRefs_(std::clamp<uint32_t>(totalRefs / 8, kScratchMinRefs, kScratchRefs)), queue_(q) {}

    uint32_t Bins() const { return bins_; }

    // The root's range is measured here rather than before the workers start, so they can help.
    void RunRoot(Task* root, Workspace* ws) {
        root->range = MeasureRange(root->range.begin, root->range.end, root->range.depth);
        RunTask(root, ws);
    }

    void RunTask(Task* task, Workspace* ws) {
        BinSet* bins = ws->Slot(task->range.depth, 0);
        bins->valid = false;
        if (!task->carried.empty()) {
            bins->LoadFrom(task->carried, bins_);
            std::vector<uint8_t>().swap(task->carried);
        }
        Build(task, task->range, bins, ws);
        task->code.shrink_to_fit();
    }

private:
    PrimRef* refs_;
    uint32_t bins_;
    uint32_t maxLeaf_;
    uint32_t scratchRefs_;
    TaskQueue* queue_;

    static void MakeLeaf(Task* task, const Range& r) { task->code.push_back(uint8_t(r.end - r.begin)); }

    // Exact box and centroid box of refs[begin, end), in chunks for large ranges.
    Range MeasureRange(uint32_t begin, uint32_t end, uint32_t depth) {
        const uint32_t chunks = Chunks(end - begin);
        std::vector<Side> sides(chunks);
        queue_->ParallelFor(chunks, [&](uint32_t c) {
            const uint32_t b = begin + c * kChunkRefs, e = std::min(end, b + kChunkRefs);
            for (uint32_t i = b; i < e; ++i) sides[c].Add(refs_[i]);
        });
        Side all;
        for (const Side& s : sides) all.Merge(s);
        return all.ToRange(begin, end, depth);
    }

    // Bins a node's references on its own grid (the root, and children whose inherited grid was loose).
    void BinOwnGrid(const Range& r, BinSet* bins) {
        alignas(16) float clo[4], chi[4];
        _mm_store_ps(clo, r.clo);
        _mm_store_ps(chi, r.chi);
        bins->Reset(MakeGrid(clo, chi, bins_), bins_);
        const uint32_t count = r.end - r.begin;
        if (count < kChunkedMin) {
            for (uint32_t i = r.begin; i < r.end; ++i) bins->Add(refs_[i], Centroid(refs_[i]), bins_);
            return;
        }
        std::vector<std::unique_ptr<BinSet>> parts(Chunks(count));
        queue_->ParallelFor(uint32_t(parts.size()), [&](uint32_t c) {
            parts[c] = std::make_unique<BinSet>(bins_);
            parts[c]->Reset(bins->grid, bins_);
            const uint32_t b = r.begin + c * kChunkRefs, e = std::min(r.end, b + kChunkRefs);
            for (uint32_t i = b; i < e; ++i) parts[c]->Add(refs_[i], Centroid(refs_[i]), bins_);
        });
        for (const auto& p : parts) bins->Merge(*p, bins_);
    }

    // The cheapest split between bins; axis -1 when none exists.
    BinSplit BestBinSplit(const BinSet& bins) const {
        BinSplit best;
        for (int a = 0; a < 3; ++a) {
            if (bins.grid.qs[a] == 0) continue;
            const Bin* box = &bins.box[a * bins_];
            const uint32_t* count = &bins.count[a * bins_];
            double rightArea[kMaxBins];
            uint32_t rightCount[kMaxBins];
            __m128 lo = _mm_set1_ps(INFINITY), hi = _mm_set1_ps(-INFINITY);
            uint32_t n = 0;
            for (uint32_t k = bins_ - 1; k > 0; --k) {
                lo = _mm_min_ps(lo, box[k].lo);
                hi = _mm_max_ps(hi, box[k].hi);
                n += count[k];
                rightArea[k] = HalfArea(lo, hi);
                rightCount[k] = n;
            }
            lo = _mm_set1_ps(INFINITY); hi = _mm_set1_ps(-INFINITY);
            n = 0;
            for (uint32_t k = 0; k + 1 < bins_; ++k) {
                lo = _mm_min_ps(lo, box[k].lo);
                hi = _mm_max_ps(hi, box[k].hi);
                n += count[k];
                if (n == 0 || rightCount[k + 1] == 0) continue;
                const double cost = HalfArea(lo, hi) * n + rightArea[k + 1] * rightCount[k + 1];
                if (cost < best.cost) { best.cost = cost; best.axis = a; best.bin = k + 1; best.leftCount = n; }
            }
        }
        return best;
    }

    // The child's grid inherited from the parent's: the split axis cut at the split plane.
    Grid ChildGrid(const Grid& parent, const BinSplit& s, bool left) const {
        alignas(16) float lo[4], hi[4];
        std::copy(parent.lo, parent.lo + 4, lo);
        std::copy(parent.hi, parent.hi + 4, hi);
        const int a = s.axis;
        const float plane = float(double(parent.lo[a]) + (double(parent.hi[a]) - double(parent.lo[a])) * s.bin / bins_);
        (left ? hi : lo)[a] = plane;
        return MakeGrid(lo, hi, bins_);
    }

    // A binned child's range from its bins: the box is exact (the union of its bins on one axis); the
    // centroid box is the span of its occupied bins, a slight superset, used only to re-bin and for the
    // median fallback. Marks the bins for re-binning when the centroids fill too little of the grid.
    Range RangeFromBins(uint32_t begin, uint32_t end, uint32_t depth, BinSet* bins) const {
        Range r{begin, end, _mm_set1_ps(INFINITY), _mm_set1_ps(-INFINITY), _mm_setzero_ps(), _mm_setzero_ps(), depth};
        for (uint32_t k = 0; k < bins_; ++k) {
            r.lo = _mm_min_ps(r.lo, bins->box[k].lo);
            r.hi = _mm_max_ps(r.hi, bins->box[k].hi);
        }
        alignas(16) float clo[4] = {0, 0, 0, 0}, chi[4] = {0, 0, 0, 0};
        const Grid& g = bins->grid;
        for (int a = 0; a < 3; ++a) {
            clo[a] = g.lo[a];
            chi[a] = g.hi[a];
            if (g.qs[a] == 0) continue;
            const uint32_t* count = &bins->count[a * bins_];
            uint32_t kmin = 0, kmax = bins_ - 1;
            while (kmin < kmax && count[kmin] == 0) ++kmin;
            while (kmax > kmin && count[kmax] == 0) --kmax;
            if (float(kmax - kmin + 1) < kLooseGrid * float(bins_)) bins->valid = false;
            const double w = (double(g.hi[a]) - double(g.lo[a])) / bins_;
            if (kmin > 0) clo[a] = float(double(g.lo[a]) + w * kmin);
            if (kmax + 1 < bins_) chi[a] = float(double(g.lo[a]) + w * (kmax + 1));
        }
        r.clo = _mm_load_ps(clo);
        r.chi = _mm_load_ps(chi);
        return r;
    }

    Range RangeFromRefs(uint32_t begin, uint32_t end, uint32_t depth) const {
        Side side;
        for (uint32_t i = begin; i < end; ++i) side.Add(refs_[i]);
        return side.ToRange(begin, end, depth);
    }

    // Partitions by the chosen split and bins every reference into its child's bins in the same pass.
    void PartitionAndBin(const Range& r, const BinSet& bins, const BinSplit& s, Range* left, Range* right,
                         BinSet* leftBins, BinSet* rightBins, Workspace* ws) {
        leftBins->Reset(ChildGrid(bins.grid, s, true), bins_);
        rightBins->Reset(ChildGrid(bins.grid, s, false), bins_);
        const uint32_t count = r.end - r.begin;
        uint32_t mid;
        if (count <= scratchRefs_) {
            // Both loops give the same result; which is faster depends on how often the side changes
            // from one reference to the next (coherent meshes: rarely, and a branch predicts well).
            const bool masked = SideChangesOften(r, bins.grid, s);
            PrimRef* const refs = refs_ + r.begin;
            PrimRef* const scratch = ws->Scratch(count);
            uint32_t l;
            switch (s.axis * 2 + int(masked)) {
                case 0: l = PartitionCopy<0, false>(refs, count, bins.grid, s.bin, leftBins, rightBins, scratch); break;
                case 1: l = PartitionCopy<0, true>(refs, count, bins.grid, s.bin, leftBins, rightBins, scratch); break;
                case 2: l = PartitionCopy<1, false>(refs, count, bins.grid, s.bin, leftBins, rightBins, scratch); break;
                case 3: l = PartitionCopy<1, true>(refs, count, bins.grid, s.bin, leftBins, rightBins, scratch); break;
                case 4: l = PartitionCopy<2, false>(refs, count, bins.grid, s.bin, leftBins, rightBins, scratch); break;
                default: l = PartitionCopy<2, true>(refs, count, bins.grid, s.bin, leftBins, rightBins, scratch); break;
            }
            std::memcpy(static_cast<void*>(refs), scratch, sizeof(PrimRef) * count);
            mid = r.begin + l;
        } else {
            switch (s.axis) {
                case 0: mid = PartitionLoop<0>(r, bins.grid, s.bin, leftBins, rightBins); break;
                case 1: mid = PartitionLoop<1>(r, bins.grid, s.bin, leftBins, rightBins); break;
                default: mid = PartitionLoop<2>(r, bins.grid, s.bin, leftBins, rightBins); break;
            }
        }
        const uint32_t d = r.depth + 1;
        *left = mid - r.begin > kSweepMax ? RangeFromBins(r.begin, mid, d, leftBins) : RangeFromRefs(r.begin, mid, d);
        *right = r.end - mid > kSweepMax ? RangeFromBins(mid, r.end, d, rightBins) : RangeFromRefs(mid, r.end, d);
        if (mid - r.begin <= kSweepMax) leftBins->valid = false;
        if (r.end - mid <= kSweepMax) rightBins->valid = false;
    }

    // Samples the first references: does the side flip often enough that a branch on it would mispredict?
    bool SideChangesOften(const Range& r, const Grid& g, const BinSplit& s) const {
        const uint32_t n = std::min<uint32_t>(r.end - r.begin, kSideSample);
        const __m128 splitAt = _mm_set1_ps(float(s.bin));
        uint32_t changes = 0, previous = 2;
        for (uint32_t i = 0; i < n; ++i) {
            const uint32_t left = g.Left(Centroid(refs_[r.begin + i]), splitAt, s.axis);
            changes += uint32_t(previous != 2 && left != previous);
            previous = left;
        }
        return changes * 4 > n;
    }

    // Out-of-place partition of refs[0, count) into scratch (left side forward from 0, right side
    // backward from count), binning each reference into its side's bins. Each reference is written to
    // both ends and only its side's cursor advances, so the side decision never becomes a branch there;
    // kMasked also selects the bins by mask (for nodes whose side flips often). Returns the left count.
    template <int kAxis, bool kMasked>
    uint32_t PartitionCopy(const PrimRef* refs, uint32_t count, const Grid& node, uint32_t splitBin,
                           BinSet* leftBins, BinSet* rightBins, PrimRef* scratch) const {
        const Grid gl = leftBins->grid, gr = rightBins->grid;
        Bin* const lbox = leftBins->box.get();
        Bin* const rbox = rightBins->box.get();
        uint32_t* const lcount = leftBins->count.get();
        uint32_t* const rcount = rightBins->count.get();
        const __m128 p = node.p, cminp = node.cminp, q = node.q, splitAt = _mm_set1_ps(float(splitBin));
        const uint32_t bins = bins_;
        const uintptr_t rboxBits = reinterpret_cast<uintptr_t>(rbox), rcountBits = reinterpret_cast<uintptr_t>(rcount);
        const uintptr_t boxDiff = reinterpret_cast<uintptr_t>(lbox) ^ rboxBits;
        const uintptr_t countDiff = reinterpret_cast<uintptr_t>(lcount) ^ rcountBits;
        uint32_t l = 0, rr = count;
        for (uint32_t i = 0; i < count; ++i) {
            const __m128 lo = LoadLo(refs[i]), hi = LoadHi(refs[i]);
            const __m128 c2 = _mm_add_ps(lo, hi);
            const __m128 t = _mm_mul_ps(_mm_sub_ps(_mm_mul_ps(c2, p), cminp), q);  // Grid::Left, inlined
            const uint32_t left = uint32_t(_mm_movemask_ps(_mm_cmpnge_ps(t, splitAt)) >> kAxis) & 1u;
            _mm_store_ps(scratch[l].lo, lo);
            _mm_store_ps(scratch[l].hi, hi);
            _mm_store_ps(scratch[rr - 1].lo, lo);
            _mm_store_ps(scratch[rr - 1].hi, hi);
            l += left;
            rr -= left ^ 1u;
            const __m128i kl = _mm_cvttps_epi32(gl.Coord(c2)), kr = _mm_cvttps_epi32(gr.Coord(c2));
            const __m128i sel = _mm_set1_epi32(-int(left));
            const __m128i k = _mm_or_si128(_mm_and_si128(sel, kl), _mm_andnot_si128(sel, kr));
            Bin* box;
            uint32_t* cnt;
            if (kMasked) {
                // Selected by mask, not by `?:`: the compiler turns that into a branch.
                const uintptr_t pick = uintptr_t(0) - uintptr_t(left);
                box = reinterpret_cast<Bin*>(rboxBits ^ (boxDiff & pick));
                cnt = reinterpret_cast<uint32_t*>(rcountBits ^ (countDiff & pick));
            } else if (left) {
                box = lbox;
                cnt = lcount;
            } else {
                box = rbox;
                cnt = rcount;
            }
            AddToBins(box, cnt, k, lo, hi, bins);
        }
        return l;
    }

    // In-place two-pointer partition (nodes above the scratch size: the top few levels).
    // Kept small so that the three grids stay in registers: no running boxes here (they come from bins).
    template <int kAxis>
    uint32_t PartitionLoop(const Range& r, const Grid& node, uint32_t splitBin, BinSet* leftBins, BinSet* rightBins) {
        const Grid gl = leftBins->grid, gr = rightBins->grid;
        Bin* const lbox = leftBins->box.get();
        Bin* const rbox = rightBins->box.get();
        uint32_t* const lcount = leftBins->count.get();
        uint32_t* const rcount = rightBins->count.get();
        const __m128 p = node.p, cminp = node.cminp, q = node.q, splitAt = _mm_set1_ps(float(splitBin));
        const uint32_t bins = bins_;
        // Left iff trunc(clamp(t)) < splitBin, i.e. !(t >= splitBin) (NaN clamps to bin 0): the node's
        // own binning decision, bit for bit.
        auto isLeft = [&](__m128 c2) {
            const __m128 t = _mm_mul_ps(_mm_sub_ps(_mm_mul_ps(c2, p), cminp), q);
            return (_mm_movemask_ps(_mm_cmpnge_ps(t, splitAt)) & (1 << kAxis)) != 0;
        };
        auto add = [bins](const Grid& g, Bin* box, uint32_t* count, const PrimRef& ref, __m128 c2) {
            AddToBins(box, count, _mm_cvttps_epi32(g.Coord(c2)), LoadLo(ref), LoadHi(ref), bins);
        };
        PrimRef* const refs = refs_;
        uint32_t i = r.begin, j = r.end;
        for (;;) {
            __m128 ci = _mm_setzero_ps(), cj = _mm_setzero_ps();
            for (; i < j; ++i) {
                ci = Centroid(refs[i]);
                if (!isLeft(ci)) break;
                add(gl, lbox, lcount, refs[i], ci);
            }
            for (; i < j; --j) {
                cj = Centroid(refs[j - 1]);
                if (isLeft(cj)) break;
                add(gr, rbox, rcount, refs[j - 1], cj);
            }
            if (i >= j) break;
            std::swap(refs[i], refs[j - 1]);
            add(gl, lbox, lcount, refs[i++], cj);
            add(gr, rbox, rcount, refs[--j], ci);
        }
        return i;
    }

    void Build(Task* task, Range r, BinSet* bins, Workspace* ws) {
        const uint32_t count = r.end - r.begin;
        if (count == 1) { MakeLeaf(task, r); return; }
        const bool forceMedian = r.depth + HalvingLevels(count, maxLeaf_) >= kMaxDepth;
        if (forceMedian && count <= maxLeaf_) { MakeLeaf(task, r); return; }

        BinSet* leftBins = ws->Slot(r.depth + 1, 0);
        BinSet* rightBins = ws->Slot(r.depth + 1, 1);
        leftBins->valid = rightBins->valid = false;
        Range left, right;
        double cost = INFINITY;
        bool found = false;
        if (!forceMedian) {
            if (count <= kSweepMax) {
                found = SmallNodeSplit(refs_, r, &cost, &left, &right);
            } else {
                if (!bins->valid) BinOwnGrid(r, bins);
                const BinSplit s = BestBinSplit(*bins);
                if (s.axis >= 0) {
                    found = true;
                    cost = s.cost;
                    PartitionAndBin(r, *bins, s, &left, &right, leftBins, rightBins, ws);
                }
            }
        }
        if (count <= maxLeaf_) {
            const double nodeArea = HalfArea(r.lo, r.hi);
            if (!found || !(nodeArea + cost < nodeArea * count)) { MakeLeaf(task, r); return; }
        }
        if (!found) {
            // No usable SAH split (identical centroids, depth budget): halve; by centroid when they differ.
            int wide = 0;
            for (int a = 1; a < 3; ++a)
                if (double(Lane(r.chi, a)) - double(Lane(r.clo, a)) > double(Lane(r.chi, wide)) - double(Lane(r.clo, wide))) wide = a;
            const uint32_t mid = r.begin + count / 2;
            if (Lane(r.chi, wide) > Lane(r.clo, wide)) {
                std::nth_element(refs_ + r.begin, refs_ + mid, refs_ + r.end, [wide](const PrimRef& x, const PrimRef& y) {
                    const float cx = Lane(Centroid(x), wide), cy = Lane(Centroid(y), wide);
                    return cx < cy || (cx == cy && x.id < y.id);
                });
            }
            left = RangeFromRefs(r.begin, mid, r.depth + 1);
            right = RangeFromRefs(mid, r.end, r.depth + 1);
        }

        if (right.end - right.begin >= kSpawnRefs) {
            task->code.push_back(kCodeInnerSpawned);
            auto child = std::make_unique<Task>();
            child->range = right;
            if (rightBins->valid) rightBins->SaveTo(&child->carried, bins_);
            Task* raw = child.get();
            task->children.push_back(std::move(child));
            queue_->Push(raw);
            Build(task, left, leftBins, ws);
        } else {
            task->code.push_back(kCodeInner);
            Build(task, left, leftBins, ws);
            Build(task, right, rightBins, ws);
        }
    }
};

}  // namespace

Bvh BuildBinnedSah(std::vector<PrimRef>& refs, const BuildOptions& options) {
    Bvh bvh;
    if (refs.empty()) return bvh;
    TaskQueue queue;
    {
        BinnedBuilder builder(refs.data(), uint32_t(refs.size()), options, &queue);
        Task root;
        root.range.begin = 0;
        root.range.end = uint32_t(refs.size());
        root.range.depth = 1;
        queue.Push(&root);
        auto work = [&builder, &queue, &root] {
            const FloatModeGuard mode;  // a new thread's mode is not the caller's guarded one everywhere
            Workspace ws(builder.Bins());
            queue.Work([&](Task* t) {
                if (t == &root) builder.RunRoot(t, &ws);
                else builder.RunTask(t, &ws);
            });
        };
        std::vector<std::thread> workers;
        for (uint32_t i = 1; i < std::max<uint32_t>(options.threads, 1); ++i) workers.emplace_back(work);
        work();
        for (auto& w : workers) w.join();

        // Expand the codes (boxes and ids come from the references, released as they are read), then free them.
        bvh.nodes.resize(CountNodes(root));
        bvh.primIds.resize(refs.size());
        ExpandCodes(refs.data(), refs.size(), root, bvh.nodes.data(), bvh.primIds.data(), &bvh.stats);
    }
    std::vector<PrimRef>().swap(refs);
    return bvh;
}

}  // namespace asval::builder::detail
