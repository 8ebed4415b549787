// Private: the LBVH's first phase, references sorted into Morton order of their centroids.
#pragma once

#include <cstdint>
#include <vector>

#include "asval/builder/build_input.h"

namespace asval::builder::detail {

// Reorders `refs` by the Morton code of their centroids (3 * bitsPerAxis bits, bitsPerAxis in 1..21;
// stable: equal codes keep their input order, so the order is deterministic) and returns the sorted codes:
// in `codes` when they have at most 32 bits (the default 30; 4 bytes each keep the top-down pass's binary
// searches in cache), else in `wideCodes`. The other array is left empty.
void SortByMorton(std::vector<PrimRef>& refs, uint32_t bitsPerAxis, std::vector<uint32_t>* codes,
                  std::vector<uint64_t>* wideCodes);

}  // namespace asval::builder::detail
