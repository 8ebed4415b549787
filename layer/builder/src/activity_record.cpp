#include <algorithm>

#include "asval/builder/activity_record.h"

namespace asval::builder {

ActivityDiff CompareActivity(const ActivityRecord& before, const ActivityRecord& after,
                             ActivityChange* firstChanges, size_t maxReport) {
    ActivityDiff d;
    d.primitiveCountDiffers = before.primitiveCount != after.primitiveCount;
    d.indexHashDiffers = before.hasIndexHash && after.hasIndexHash && before.indexHash != after.indexHash;
    const uint32_t n = std::min(before.primitiveCount, after.primitiveCount);
    const size_t words = (size_t(n) + 63) / 64;
    for (size_t w = 0; w < words; ++w) {
        uint64_t a = before.activeBits[w], b = after.activeBits[w];
        if (w == words - 1 && (n & 63) != 0) {
            const uint64_t mask = (uint64_t(1) << (n & 63)) - 1;  // bits past n are not primitives
            a &= mask;
            b &= mask;
        }
        uint64_t changed = a ^ b;
        if (changed == 0) continue;
        d.changedCount += uint64_t(__builtin_popcountll(changed));
        d.becameActive += uint64_t(__builtin_popcountll(changed & b));
        d.becameInactive += uint64_t(__builtin_popcountll(changed & a));
        while (changed != 0 && d.reported < maxReport) {
            const int bit = __builtin_ctzll(changed);
            firstChanges[d.reported++] = {uint32_t(w * 64 + unsigned(bit)), ((b >> bit) & 1u) != 0};
            changed &= changed - 1;
        }
    }
    return d;
}

}  // namespace asval::builder
