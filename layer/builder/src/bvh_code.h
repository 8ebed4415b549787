// Private: the compact form both BVH builders record a tree in while building, and its expansion.
// A subtree is a pre-order byte code, one byte per node and no boxes (a 32-byte node per node would be
// the largest term of the build's peak); the boxes are recomputed from the references when the code is
// expanded into the output, once, after the build.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "bvh_internal.h"

namespace asval::builder::detail {

struct Range {
    uint32_t begin, end;
    __m128 lo, hi;    // box of the references
    __m128 clo, chi;  // box of their centroids
    uint32_t depth;   // 1 for the root
};

// Pre-order node codes. A leaf's first reference is implicit: leaves tile the task's range in order.
constexpr uint8_t kCodeInner = 0;         // both children follow in this task's code
constexpr uint8_t kCodeInnerSpawned = 0xFF;  // the left child follows; the right one is the next child task
// 1..8: a leaf of that many references

// One subtree recorded by one builder task (binned SAH: a subtree spawned for any thread; LBVH: the
// whole tree).
struct Task {
    Range range;
    std::vector<uint8_t> code;  // code[0] is this task's root
    std::vector<std::unique_ptr<Task>> children;  // spawned right subtrees, in pre-order
    std::vector<uint8_t> carried;  // builder state handed from the spawning task (binned SAH: the root's bins)
};

// Nodes the tasks recorded, all of them.
size_t CountNodes(const Task& root);

// Writes the tree into out[0, CountNodes(root)): the root at out[0], then one slot pair per inner node in
// pre-order (a spawned child task expanded where its parent names it). Leaves tile the references in
// pre-order (the root task starts at range.begin, depth range.depth). When `ids` is not null it receives
// each reference's id at the reference's index. The references are read once, front to back, and their
// pages may be released as they are (they must not be read afterwards; free them next). Frees the codes as
// it goes. Counts leaves, the largest leaf and the depth into `stats` (which starts zeroed).
void ExpandCodes(PrimRef* refs, size_t refCount, Task& root, BvhNode* out, uint32_t* ids, BuildStats* stats);

}  // namespace asval::builder::detail
