// What the layer keeps per geometry of an updatable build: one bit per primitive (active or not), counts,
// and a 128-bit fingerprint of the index values. This is all the update rules 03663/03664/03768 need.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace asval::builder {

struct Hash128 {
    uint64_t lo = 0;
    uint64_t hi = 0;
    bool operator==(const Hash128& o) const { return lo == o.lo && hi == o.hi; }
    bool operator!=(const Hash128& o) const { return !(*this == o); }
};

struct ActivityRecord {
    std::vector<uint64_t> activeBits;  // bit i of word i/64: primitive i is active
    uint32_t primitiveCount = 0;
    uint32_t activeCount = 0;
    bool hasIndexHash = false;         // indexed triangle geometry only
    Hash128 indexHash;                 // over the primitiveCount*3 index values (see index_hash.h)

    bool IsActive(uint32_t primitive) const {
        return (activeBits[primitive >> 6] >> (primitive & 63)) & 1u;
    }
    // Bytes this record holds beyond sizeof(*this).
    size_t HeapBytes() const { return activeBits.capacity() * sizeof(uint64_t); }
};

struct ActivityChange {
    uint32_t primitive = 0;
    bool becameActive = false;  // false: active before, inactive now
};

struct ActivityDiff {
    bool primitiveCountDiffers = false;  // compared over the smaller count
    uint64_t changedCount = 0;           // primitives whose state differs
    uint64_t becameActive = 0;
    uint64_t becameInactive = 0;
    size_t reported = 0;                 // entries written to the caller's array (first changed, ascending)
    bool indexHashDiffers = false;       // both have a hash and the hashes differ (VUID 03768)
};

// Compares `before` (the source build) with `after` (the update's inputs). Writes up to `maxReport` of the
// first changed primitives, in ascending order, into `firstChanges`. Word-wise XOR: no allocation.
ActivityDiff CompareActivity(const ActivityRecord& before, const ActivityRecord& after,
                             ActivityChange* firstChanges, size_t maxReport);

}  // namespace asval::builder
