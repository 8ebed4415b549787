// 128-bit fingerprint of an index range, for VUID 03768 (an update must not change index values).
// Four independent lanes; each step xor-rotate-multiplies by an odd constant, a bijection of the lane
// state, so changing any single 8-byte word always changes that lane's final state. Not cryptographic.
#pragma once

#include <cstddef>
#include <cstdint>

#include "asval/builder/activity_record.h"

namespace asval::builder {

// Hashes `bytes` bytes at `data`; `seed` separates index types (the caller passes the element size).
Hash128 HashIndexBytes(const void* data, size_t bytes, uint64_t seed);

// The same hash, streamed: Blocks() takes whole 32-byte blocks (in order), Finish() the tail (< 32 bytes)
// and the total length. HashIndexBytes(d, n, s) == streamed Blocks(d, n & ~31) + Finish(d + (n & ~31), n & 31, n).
// Lets the classifier hash each chunk of indices while it is still in cache.
class IndexHasher {
public:
    explicit IndexHasher(uint64_t seed);
    void Blocks(const void* data, size_t bytes);  // bytes % 32 == 0
    Hash128 Finish(const void* tail, size_t tailBytes, uint64_t totalBytes);

private:
    uint64_t h_[4];
};

}  // namespace asval::builder
