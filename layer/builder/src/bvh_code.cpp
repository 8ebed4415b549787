// Expansion of recorded codes into BvhNodes (see bvh_code.h).
#include "bvh_code.h"

#include <cmath>

namespace asval::builder::detail {
namespace {

class Expander {
public:
    Expander(const PrimRef* refs, BvhNode* out, BuildStats* stats) : refs_(refs), out_(out), stats_(stats) {}

    void Expand(Task& t) {
        State s{&t, 0, 1, 0, end_, t.range.begin};
        // Local slots: the root, then one pair per inner node; a spawned right child's slot is counted
        // here (its code[0] is in the child task). Local slots 1.. map to base + slot - 1.
        end_ += uint32_t(t.code.size() + t.children.size()) - 1;
        __m128 lo, hi;
        Node(s, t.rootSlot, t.range.depth, &lo, &hi);
        std::vector<uint8_t>().swap(t.code);
        for (auto& child : t.children) Expand(*child);
    }

private:
    struct State {
        Task* task;
        size_t pos;         // next code byte
        uint32_t nextLocal; // next local slot pair
        size_t child;       // next child task
        uint32_t base;      // global slot of local slot 1
        uint32_t cursor;    // first reference of the next leaf
    };

    void Node(State& s, uint32_t slot, uint32_t depth, __m128* lo, __m128* hi) {
        const uint8_t c = s.task->code[s.pos++];
        BvhNode& n = out_[slot];
        if (depth > stats_->maxDepth) stats_->maxDepth = depth;
        if (c != kCodeInner && c != kCodeInnerSpawned) {
            ++stats_->leaves;
            if (c > stats_->maxLeafSize) stats_->maxLeafSize = c;
            __m128 l = _mm_set1_ps(INFINITY), h = _mm_set1_ps(-INFINITY);
            for (uint32_t i = s.cursor; i < s.cursor + c; ++i) {
                l = _mm_min_ps(l, LoadLo(refs_[i]));
                h = _mm_max_ps(h, LoadHi(refs_[i]));
            }
            StoreNodeBox(n, l, h);
            n.leftOrFirst = s.cursor;
            n.count = c;
            s.cursor += c;
            *lo = l; *hi = h;
            return;
        }
        const uint32_t left = s.base + s.nextLocal - 1;
        s.nextLocal += 2;
        // The spawned child was pushed before any spawned inside the left subtree: take it first.
        Task* spawned = c == kCodeInnerSpawned ? s.task->children[s.child++].get() : nullptr;
        __m128 llo, lhi, rlo, rhi;
        Node(s, left, depth + 1, &llo, &lhi);
        if (spawned) {
            Task& child = *spawned;
            child.rootSlot = left + 1;
            rlo = child.range.lo; rhi = child.range.hi;
            s.cursor = child.range.end;
        } else {
            Node(s, left + 1, depth + 1, &rlo, &rhi);
        }
        *lo = _mm_min_ps(llo, rlo);
        *hi = _mm_max_ps(lhi, rhi);
        StoreNodeBox(n, *lo, *hi);
        n.leftOrFirst = left;
        n.count = 0;
    }

    const PrimRef* refs_;
    BvhNode* out_;
    BuildStats* stats_;
    uint32_t end_ = 1;  // out_[0] is the root
};

}  // namespace

size_t CountNodes(const Task& t) {
    size_t n = t.code.size();
    for (const auto& c : t.children) n += CountNodes(*c);
    return n;
}

void ExpandCodes(const PrimRef* refs, Task& root, BvhNode* out, BuildStats* stats) {
    root.rootSlot = 0;
    Expander(refs, out, stats).Expand(root);
}

}  // namespace asval::builder::detail
