// Expansion of recorded codes into BvhNodes (see bvh_code.h).
#include "bvh_code.h"

#include "page_release.h"

#include <cmath>

namespace asval::builder::detail {
namespace {

// Expands in one global pre-order: a spawned child task is expanded where its parent's code names it, so
// leaves take the references strictly front to back (a spawned task's range is the right subtree's, which
// follows the left one's) and slots are handed out in the same order. That is what lets the references be
// released while the output is written (page_release.h).
class Expander {
public:
    Expander(PrimRef* refs, size_t refCount, BvhNode* out, uint32_t* ids, BuildStats* stats)
        : refs_(refs), out_(out), ids_(ids), stats_(stats), release_(refs, refCount * sizeof(PrimRef)) {}

    void Expand(Task& root) {
        cursor_ = root.range.begin;
        Cursor c{&root, 0, 0};
        __m128 lo, hi;
        Node(c, 0, root.range.depth, &lo, &hi);
        std::vector<uint8_t>().swap(root.code);
    }

private:
    struct Cursor {
        Task* task;
        size_t pos;    // next code byte of `task`
        size_t child;  // next spawned child of `task`
    };

    void Node(Cursor& c, uint32_t slot, uint32_t depth, __m128* lo, __m128* hi) {
        const uint8_t code = c.task->code[c.pos++];
        BvhNode& n = out_[slot];
        if (depth > stats_->maxDepth) stats_->maxDepth = depth;
        if (code != kCodeInner && code != kCodeInnerSpawned) {
            ++stats_->leaves;
            if (code > stats_->maxLeafSize) stats_->maxLeafSize = code;
            __m128 l = _mm_set1_ps(INFINITY), h = _mm_set1_ps(-INFINITY);
            for (uint32_t i = cursor_; i < cursor_ + code; ++i) {
                l = _mm_min_ps(l, LoadLo(refs_[i]));
                h = _mm_max_ps(h, LoadHi(refs_[i]));
                if (ids_) ids_[i] = refs_[i].id;
            }
            StoreNodeBox(n, l, h);
            n.leftOrFirst = cursor_;
            n.count = code;
            cursor_ += code;
            release_.Consumed(size_t(cursor_) * sizeof(PrimRef));
            *lo = l; *hi = h;
            return;
        }
        const uint32_t left = next_;
        next_ += 2;
        // The spawned child was pushed before any spawned inside the left subtree: take it first.
        Task* spawned = code == kCodeInnerSpawned ? c.task->children[c.child++].get() : nullptr;
        __m128 llo, lhi, rlo, rhi;
        Node(c, left, depth + 1, &llo, &lhi);
        if (spawned) {
            Cursor sc{spawned, 0, 0};
            Node(sc, left + 1, depth + 1, &rlo, &rhi);
            std::vector<uint8_t>().swap(spawned->code);
        } else {
            Node(c, left + 1, depth + 1, &rlo, &rhi);
        }
        *lo = _mm_min_ps(llo, rlo);
        *hi = _mm_max_ps(lhi, rhi);
        StoreNodeBox(n, *lo, *hi);
        n.leftOrFirst = left;
        n.count = 0;
    }

    PrimRef* refs_;
    BvhNode* out_;
    uint32_t* ids_;
    BuildStats* stats_;
    PageReleaser release_;
    uint32_t next_ = 1;  // next free slot pair; out_[0] is the root
    uint32_t cursor_ = 0;  // first reference of the next leaf
};

}  // namespace

size_t CountNodes(const Task& t) {
    size_t n = t.code.size();
    for (const auto& c : t.children) n += CountNodes(*c);
    return n;
}

void ExpandCodes(PrimRef* refs, size_t refCount, Task& root, BvhNode* out, uint32_t* ids, BuildStats* stats) {
    Expander(refs, refCount, out, ids, stats).Expand(root);
}

}  // namespace asval::builder::detail
