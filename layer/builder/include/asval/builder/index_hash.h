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

}  // namespace asval::builder
