// 128-bit fingerprint of an index range, for VUID 03768 (an update must not change index values).
// Four independent lanes; each step xor-rotate-multiplies by an odd constant, a bijection of the lane
// state, so changing any single 8-byte word always changes that lane's final state. Not cryptographic.
//
// The range is hashed in blocks of 64 triangles' indices (IndexHashBlockBytes), each on its own (HashIndexBlock),
// and the block hashes, in order, are hashed again (IndexHashCombiner). The blocks let a device compute them in
// parallel where the build reads the indices, so that the host only combines one hash per 64 triangles: the
// layer's reducing dispatch (layer/capture/shaders/reduce_inputs.comp) computes HashIndexBlock bit for bit.
#pragma once

#include <cstddef>
#include <cstdint>

#include "asval/builder/activity_record.h"

namespace asval::builder {

// Triangles per block, and the bytes of one block's indices for an element size of `indexBytes` (1, 2 or 4): a
// multiple of the lanes' 32 bytes for each.
inline constexpr uint32_t kIndexHashBlockTriangles = 64;
constexpr size_t IndexHashBlockBytes(uint64_t indexBytes) { return 3 * kIndexHashBlockTriangles * indexBytes; }

// Hashes `bytes` bytes at `data`; `indexBytes` is the element size (1, 2 or 4), which also seeds the hash, so
// that index types are told apart.
Hash128 HashIndexBytes(const void* data, size_t bytes, uint64_t indexBytes);

// One block of it: `bytes` (at most IndexHashBlockBytes; less for the last block only) at `data`.
Hash128 HashIndexBlock(const void* data, size_t bytes, uint64_t indexBytes);

// The lanes, streamed: Blocks() takes whole 32-byte steps (in order), Finish() the tail (< 32 bytes) and the
// total length. HashIndexBlock(d, n, s) == Blocks(d, n & ~31) then Finish(d + (n & ~31), n & 31, n).
class IndexHasher {
public:
    explicit IndexHasher(uint64_t seed);
    void Blocks(const void* data, size_t bytes);  // bytes % 32 == 0
    Hash128 Finish(const void* tail, size_t tailBytes, uint64_t totalBytes);

private:
    uint64_t h_[4];
};

// The block hashes of a range, in order, into its hash: HashIndexBytes(d, n, s) == Add(HashIndexBlock(block k))
// for each block k, then Finish(n). Lets the classifier hash each chunk while it is still in cache, and the layer
// combine the hashes its dispatch wrote.
class IndexHashCombiner {
public:
    explicit IndexHashCombiner(uint64_t indexBytes);
    void Add(const Hash128& block);
    // `count` block hashes stored as a device writes them: 16 bytes each, lo then hi, little-endian. The same as
    // Add() for each, in order, with no call per hash (two hashes are one step of the lanes).
    void AddHashes(const void* hashes, size_t count);
    // Each block of `bytes` at `data` (its start a block's), added in order.
    void AddBlocks(const void* data, size_t bytes);
    Hash128 Finish(uint64_t totalBytes);

private:
    IndexHasher outer_;
    uint64_t indexBytes_;
    uint64_t pending_[2] = {0, 0};  // a block hash waiting for the next: the lanes take 32 bytes at a time
    bool hasPending_ = false;
};

}  // namespace asval::builder
