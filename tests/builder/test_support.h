// Shared helpers for the builder tests: deterministic RNG, raw component writers, oracle comparison.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "asval/builder/classify.h"
#include "oracle.h"

namespace testsupport {

// splitmix64: deterministic, seedable, independent of the standard library's distributions.
struct Rng {
    uint64_t s;
    explicit Rng(uint64_t seed) : s(seed) {}
    uint64_t Next() {
        uint64_t z = (s += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    uint32_t Below(uint32_t n) { return uint32_t((Next() >> 32) * n >> 32); }
    double Unit() { return double(Next() >> 11) * 0x1p-53; }
};

// Scale factor for long runs: ASVAL_TEST_SCALE=100 multiplies the randomised trial counts.
uint64_t TestScale();

// Writes the raw code of component `comp` (0..2) of a vertex of `format` at `vertex`.
// Float32: the 32-bit pattern; Float16: 16 bits; norm formats: the integer code; A2B10G10R10: 10 bits.
void WriteComponent(VkFormat format, uint8_t* vertex, int comp, uint32_t code);
// Number of X/Y/Z components stored (2 or 3) and bits per component code.
int StoredXyz(VkFormat format);
unsigned CodeBits(VkFormat format);

struct Mismatch {
    uint64_t count = 0;
    std::string first;  // description of the first mismatching primitive
};

// Runs the builder's ClassifyTriangles and the oracle on every triangle of `view`; counts any difference in
// active / degenerate / same-index / undefined state, in the record's bits and in the totals.
Mismatch CompareWithOracle(const asval::builder::TriangleGeometryView& view);

}  // namespace testsupport
