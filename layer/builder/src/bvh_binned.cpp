// Binned SAH builder (default mode). Top-down; each node bins reference centroids on all three axes,
// sweeps the bins for the cheapest SAH split and partitions in place. Subtrees above kSpawnRefs become
// tasks that any thread may run; each task records its subtree as a pre-order byte code (1 byte per node,
// no boxes), and the codes are expanded into the output in a fixed order, so the tree is identical for
// every thread count. Boxes are recomputed from the references during that expansion: the build never
// holds two copies of the tree (peak = references + tree + ids, not references + 2 x tree).
#include <emmintrin.h>

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>

#include "bvh_code.h"

namespace asval::builder::detail {
namespace {

constexpr uint32_t kSpawnRefs = 4096;
constexpr uint32_t kMaxBins = 64;
constexpr uint32_t kSweepMax = 12;  // nodes this small get an exact SAH sweep instead of bins

class Queue {
public:
    void Push(Task* t) {
        { std::lock_guard<std::mutex> l(mutex_); queue_.push_back(t); ++pending_; }
        cv_.notify_one();
    }
    // Runs tasks until every pushed task (and those they push) has finished.
    template <typename Fn>
    void Work(Fn&& run) {
        std::unique_lock<std::mutex> l(mutex_);
        for (;;) {
            if (!queue_.empty()) {
                Task* t = queue_.front();
                queue_.pop_front();
                l.unlock();
                run(t);
                l.lock();
                if (--pending_ == 0) cv_.notify_all();
            } else if (pending_ == 0) {
                return;
            } else {
                cv_.wait(l);
            }
        }
    }

private:
    std::mutex mutex_;
    std::condition_variable cv_;
    std::deque<Task*> queue_;
    uint32_t pending_ = 0;
};

struct Bin {
    __m128 lo, hi;
};

class BinnedBuilder {
public:
    BinnedBuilder(PrimRef* refs, const BuildOptions& o, Queue* q)
        : refs_(refs), bins_(std::clamp<uint32_t>(o.bins, 2, kMaxBins)),
          maxLeaf_(std::clamp<uint32_t>(o.maxLeafSize, 1, 8)), queue_(q) {}

    void RunTask(Task* task) {
        Build(task, task->range);
        task->code.shrink_to_fit();
    }

private:
    PrimRef* refs_;
    uint32_t bins_;
    uint32_t maxLeaf_;
    Queue* queue_;

    static void MakeLeaf(Task* task, const Range& r) { task->code.push_back(uint8_t(r.end - r.begin)); }

    // Running box + centroid box of one side of a split.
    struct Side {
        __m128 lo = _mm_set1_ps(INFINITY), hi = _mm_set1_ps(-INFINITY);
        __m128 clo = _mm_set1_ps(INFINITY), chi = _mm_set1_ps(-INFINITY);
        void Add(const PrimRef& ref) {
            lo = _mm_min_ps(lo, LoadLo(ref));
            hi = _mm_max_ps(hi, LoadHi(ref));
            const __m128 c = Centroid(ref);
            clo = MinKeep(clo, c);
            chi = MaxKeep(chi, c);
        }
        Range ToRange(uint32_t b, uint32_t e, uint32_t depth) const { return Range{b, e, lo, hi, clo, chi, depth}; }
    };

    static float Lane(__m128 v, int axis) {
        alignas(16) float f[4];
        _mm_store_ps(f, v);
        return f[axis];
    }

    // Full SAH sweep for small nodes: sort by centroid on each axis, evaluate every split position.
    // Returns false when no split exists (identical centroids on every axis).
    bool SweepSmall(const Range& r, double* bestCost, Range* left, Range* right) {
        constexpr uint32_t kMax = kSweepMax;
        const uint32_t count = r.end - r.begin;
        struct Entry { float key; uint32_t index; };
        Entry order[3][kMax];
        double rightArea[kMax];
        int bestAxis = -1;
        uint32_t bestSplit = 0;
        *bestCost = INFINITY;
        for (int a = 0; a < 3; ++a) {
            if (!(Lane(r.chi, a) > Lane(r.clo, a))) continue;
            Entry* o = order[a];
            for (uint32_t i = 0; i < count; ++i) {
                // Insertion sort; ties by position keep it deterministic.
                const Entry e{Lane(Centroid(refs_[r.begin + i]), a), i};
                uint32_t k = i;
                while (k > 0 && o[k - 1].key > e.key) { o[k] = o[k - 1]; --k; }
                o[k] = e;
            }
            __m128 lo = _mm_set1_ps(INFINITY), hi = _mm_set1_ps(-INFINITY);
            for (uint32_t k = count - 1; k > 0; --k) {
                lo = _mm_min_ps(lo, LoadLo(refs_[r.begin + o[k].index]));
                hi = _mm_max_ps(hi, LoadHi(refs_[r.begin + o[k].index]));
                rightArea[k] = HalfArea(lo, hi);
            }
            lo = _mm_set1_ps(INFINITY); hi = _mm_set1_ps(-INFINITY);
            for (uint32_t k = 0; k + 1 < count; ++k) {
                lo = _mm_min_ps(lo, LoadLo(refs_[r.begin + o[k].index]));
                hi = _mm_max_ps(hi, LoadHi(refs_[r.begin + o[k].index]));
                const double cost = HalfArea(lo, hi) * (k + 1) + rightArea[k + 1] * (count - k - 1);
                if (cost < *bestCost) { *bestCost = cost; bestAxis = a; bestSplit = k + 1; }
            }
        }
        if (bestAxis < 0) return false;
        PrimRef sorted[kMax];
        for (uint32_t k = 0; k < count; ++k) sorted[k] = refs_[r.begin + order[bestAxis][k].index];
        Side l, rr;
        for (uint32_t k = 0; k < count; ++k) {
            refs_[r.begin + k] = sorted[k];
            (k < bestSplit ? l : rr).Add(sorted[k]);
        }
        *left = l.ToRange(r.begin, r.begin + bestSplit, r.depth + 1);
        *right = rr.ToRange(r.begin + bestSplit, r.end, r.depth + 1);
        return true;
    }

    // Binned SAH for larger nodes. Returns false when no bin split exists.
    bool Binned(const Range& r, double* bestCost, Range* left, Range* right) {
        alignas(16) float clo[4], chi[4];
        _mm_store_ps(clo, r.clo);
        _mm_store_ps(chi, r.chi);
        // Bin coordinate t = (c * p - cmin * p) * q, p a power of two keeping tiny (subnormal) and huge
        // extents in range; garbage lanes clamp into [0, bins) and only cost quality.
        alignas(16) float p[4] = {1, 1, 1, 1}, q[4] = {0, 0, 0, 0}, cminp[4] = {0, 0, 0, 0};
        for (int a = 0; a < 3; ++a) {
            const double extent = double(chi[a]) - double(clo[a]);
            if (!(extent > 0)) continue;
            p[a] = extent < 1e-30 ? 0x1p100f : (extent > 1e37 ? 0x1p-4f : 1.0f);
            q[a] = float(double(bins_) * (1 - 1e-6) / (extent * double(p[a])));
            cminp[a] = clo[a] * p[a];
        }
        const __m128 P = _mm_load_ps(p), Q = _mm_load_ps(q), CminP = _mm_load_ps(cminp);
        const __m128 maxBin = _mm_set1_ps(float(bins_ - 1)), zero = _mm_setzero_ps();
        auto binOf = [&](const PrimRef& ref) {
            const __m128 t = _mm_mul_ps(_mm_sub_ps(_mm_mul_ps(Centroid(ref), P), CminP), Q);
            return _mm_cvttps_epi32(_mm_min_ps(_mm_max_ps(t, zero), maxBin));  // NaN -> 0
        };

        // Two bin sets, alternating by reference, so consecutive references landing in the same bin do not
        // serialise on one memory location; merged before the sweep. Each reference's three bin indices are
        // kept in its `aux` field for the partition pass.
        Bin bins[2][3][kMaxBins];
        uint32_t counts[2][3][kMaxBins] = {};
        for (int s2 = 0; s2 < 2; ++s2)
            for (int a = 0; a < 3; ++a)
                for (uint32_t k = 0; k < bins_; ++k) bins[s2][a][k] = {_mm_set1_ps(INFINITY), _mm_set1_ps(-INFINITY)};
        auto binOne = [&](PrimRef& ref, int set) {
            const __m128i ki = binOf(ref);
            const uint32_t k[3] = {uint32_t(_mm_cvtsi128_si32(ki)), uint32_t(_mm_cvtsi128_si32(_mm_srli_si128(ki, 4))),
                                   uint32_t(_mm_cvtsi128_si32(_mm_srli_si128(ki, 8)))};
            const __m128 lo = LoadLo(ref), hi = LoadHi(ref);
            for (int a = 0; a < 3; ++a) {
                Bin& b = bins[set][a][k[a]];
                b.lo = _mm_min_ps(b.lo, lo);
                b.hi = _mm_max_ps(b.hi, hi);
                ++counts[set][a][k[a]];
            }
            ref.aux = k[0] | k[1] << 8 | k[2] << 16;
        };
        uint32_t i = r.begin;
        for (; i + 1 < r.end; i += 2) {
            binOne(refs_[i], 0);
            binOne(refs_[i + 1], 1);
        }
        if (i < r.end) binOne(refs_[i], 0);
        for (int a = 0; a < 3; ++a)
            for (uint32_t k = 0; k < bins_; ++k) {
                bins[0][a][k].lo = _mm_min_ps(bins[0][a][k].lo, bins[1][a][k].lo);
                bins[0][a][k].hi = _mm_max_ps(bins[0][a][k].hi, bins[1][a][k].hi);
                counts[0][a][k] += counts[1][a][k];
            }
        int axis = -1;
        uint32_t splitBin = 0;
        *bestCost = INFINITY;
        for (int a = 0; a < 3; ++a) {
            if (q[a] == 0) continue;
            double rightArea[kMaxBins];
            uint32_t rightCount[kMaxBins];
            __m128 lo = _mm_set1_ps(INFINITY), hi = _mm_set1_ps(-INFINITY);
            uint32_t n = 0;
            for (uint32_t k = bins_ - 1; k > 0; --k) {
                lo = _mm_min_ps(lo, bins[0][a][k].lo);
                hi = _mm_max_ps(hi, bins[0][a][k].hi);
                n += counts[0][a][k];
                rightArea[k] = HalfArea(lo, hi);
                rightCount[k] = n;
            }
            lo = _mm_set1_ps(INFINITY); hi = _mm_set1_ps(-INFINITY);
            n = 0;
            for (uint32_t k = 0; k + 1 < bins_; ++k) {
                lo = _mm_min_ps(lo, bins[0][a][k].lo);
                hi = _mm_max_ps(hi, bins[0][a][k].hi);
                n += counts[0][a][k];
                if (n == 0 || rightCount[k + 1] == 0) continue;
                const double cost = HalfArea(lo, hi) * n + rightArea[k + 1] * rightCount[k + 1];
                if (cost < *bestCost) { *bestCost = cost; axis = a; splitBin = k + 1; }
            }
        }
        if (axis < 0) return false;
        // Partition by the bin index the binning pass stored, measuring each side as it is visited.
        const unsigned shift = 8u * unsigned(axis);
        auto isLeft = [&](const PrimRef& ref) { return ((ref.aux >> shift) & 0xFFu) < splitBin; };
        Side l, rr;
        i = r.begin;
        uint32_t j = r.end;
        for (;;) {
            while (i < j && isLeft(refs_[i])) l.Add(refs_[i++]);
            while (i < j && !isLeft(refs_[j - 1])) rr.Add(refs_[--j]);
            if (i >= j) break;
            std::swap(refs_[i], refs_[j - 1]);
            l.Add(refs_[i++]);
            rr.Add(refs_[--j]);
        }
        *left = l.ToRange(r.begin, i, r.depth + 1);
        *right = rr.ToRange(i, r.end, r.depth + 1);
        return true;
    }

    void Build(Task* task, Range r) {
        const uint32_t count = r.end - r.begin;
        if (count == 1) { MakeLeaf(task, r); return; }
        const bool forceMedian = r.depth + HalvingLevels(count, maxLeaf_) >= kMaxDepth;
        if (forceMedian && count <= maxLeaf_) { MakeLeaf(task, r); return; }

        Range left, right;
        double cost = INFINITY;
        bool found = false;
        if (!forceMedian) found = count <= kSweepMax ? SweepSmall(r, &cost, &left, &right) : Binned(r, &cost, &left, &right);
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
            Side l, rr;
            for (uint32_t i = r.begin; i < r.end; ++i) (i < mid ? l : rr).Add(refs_[i]);
            left = l.ToRange(r.begin, mid, r.depth + 1);
            right = rr.ToRange(mid, r.end, r.depth + 1);
        }

        if (right.end - right.begin >= kSpawnRefs) {
            task->code.push_back(kCodeInnerSpawned);
            auto child = std::make_unique<Task>();
            child->range = right;
            Task* raw = child.get();
            task->children.push_back(std::move(child));
            queue_->Push(raw);
            Build(task, left);
        } else {
            task->code.push_back(kCodeInner);
            Build(task, left);
            Build(task, right);
        }
    }
};


}  // namespace

Bvh BuildBinnedSah(std::vector<PrimRef>& refs, const BuildOptions& options) {
    Bvh bvh;
    if (refs.empty()) return bvh;
    Queue queue;
    BinnedBuilder builder(refs.data(), options, &queue);
    Task root;
    {
        Range r{};
        __m128 lo = _mm_set1_ps(INFINITY), hi = _mm_set1_ps(-INFINITY), clo = lo, chi = hi;
        for (const PrimRef& ref : refs) {
            lo = _mm_min_ps(lo, LoadLo(ref));
            hi = _mm_max_ps(hi, LoadHi(ref));
            const __m128 c = Centroid(ref);
            clo = MinKeep(clo, c);
            chi = MaxKeep(chi, c);
        }
        r.begin = 0; r.end = uint32_t(refs.size());
        r.lo = lo; r.hi = hi; r.clo = clo; r.chi = chi; r.depth = 1;
        root.range = r;
    }
    queue.Push(&root);
    auto run = [&builder](Task* t) { builder.RunTask(t); };
    std::vector<std::thread> workers;
    for (uint32_t i = 1; i < std::max<uint32_t>(options.threads, 1); ++i)
        workers.emplace_back([&queue, &run] { queue.Work(run); });
    queue.Work(run);
    for (auto& w : workers) w.join();

    // Expand the codes (boxes come from the references), then take the ids and free the references.
    bvh.nodes.resize(CountNodes(root));
    ExpandCodes(refs.data(), root, bvh.nodes.data(), &bvh.stats);
    bvh.primIds.resize(refs.size());
    for (size_t i = 0; i < refs.size(); ++i) bvh.primIds[i] = refs[i].id;
    std::vector<PrimRef>().swap(refs);
    return bvh;
}

}  // namespace asval::builder::detail
