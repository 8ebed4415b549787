#include "asval/builder/index_hash.h"

#include <cstring>

namespace asval::builder {
namespace {

constexpr uint64_t kPrime[4] = {0x9E3779B185EBCA87ull, 0xC2B2AE3D27D4EB4Full, 0x165667B19E3779F9ull,
                                0xD6E8FEB86659FD93ull};

inline uint64_t Rotl(uint64_t x, int r) { return (x << r) | (x >> (64 - r)); }

// One lane step: xor, rotate, multiply by an odd constant. Each is a bijection of the lane state for a
// fixed input word, so two inputs differing in exactly one word always leave different lane states.
inline uint64_t Step(uint64_t h, uint64_t w, uint64_t prime) { return Rotl(h ^ w, 29) * prime; }

inline uint64_t Fmix(uint64_t k) {  // murmur3 finaliser
    k ^= k >> 33; k *= 0xFF51AFD7ED558CCDull;
    k ^= k >> 33; k *= 0xC4CEB9FE1A85EC53ull;
    k ^= k >> 33;
    return k;
}

}  // namespace

Hash128 HashIndexBytes(const void* data, size_t bytes, uint64_t seed) {
    const auto* p = static_cast<const uint8_t*>(data);
    uint64_t h[4] = {seed ^ kPrime[0], seed + kPrime[1], Rotl(seed, 17) ^ kPrime[2], ~seed ^ kPrime[3]};
    size_t i = 0;
    // Four independent dependency chains: throughput rather than one multiply latency per word.
    for (; i + 32 <= bytes; i += 32) {
        uint64_t w[4];
        std::memcpy(w, p + i, 32);
        for (int l = 0; l < 4; ++l) h[l] = Step(h[l], w[l], kPrime[l]);
    }
    // Tail: zero-padded words; the length goes into the finalisation, so padding cannot collide.
    for (int l = 0; i < bytes; ++l, i += 8) {
        uint64_t w = 0;
        std::memcpy(&w, p + i, bytes - i < 8 ? bytes - i : 8);
        h[l] = Step(h[l], w, kPrime[l]);
    }
    const uint64_t len = uint64_t(bytes);
    const uint64_t a = Fmix(h[0] ^ Rotl(h[2], 23) ^ len);
    const uint64_t b = Fmix(h[1] ^ Rotl(h[3], 41) ^ (len * kPrime[0]));
    return {Fmix(a + b), Fmix(b ^ Rotl(a, 32))};
}

}  // namespace asval::builder
