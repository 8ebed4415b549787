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

IndexHasher::IndexHasher(uint64_t seed)
    : h_{seed ^ kPrime[0], seed + kPrime[1], Rotl(seed, 17) ^ kPrime[2], ~seed ^ kPrime[3]} {}

void IndexHasher::Blocks(const void* data, size_t bytes) {
    const auto* p = static_cast<const uint8_t*>(data);
    uint64_t h0 = h_[0], h1 = h_[1], h2 = h_[2], h3 = h_[3];
    // Four independent dependency chains: throughput rather than one multiply latency per word.
    for (size_t i = 0; i + 32 <= bytes; i += 32) {
        uint64_t w[4];
        std::memcpy(w, p + i, 32);
        h0 = Step(h0, w[0], kPrime[0]);
        h1 = Step(h1, w[1], kPrime[1]);
        h2 = Step(h2, w[2], kPrime[2]);
        h3 = Step(h3, w[3], kPrime[3]);
    }
    h_[0] = h0; h_[1] = h1; h_[2] = h2; h_[3] = h3;
}

Hash128 IndexHasher::Finish(const void* tail, size_t tailBytes, uint64_t totalBytes) {
    const auto* p = static_cast<const uint8_t*>(tail);
    uint64_t h[4] = {h_[0], h_[1], h_[2], h_[3]};
    // Tail: zero-padded words; the length goes into the finalisation, so padding cannot collide.
    size_t i = 0;
    for (int l = 0; i < tailBytes; ++l, i += 8) {
        uint64_t w = 0;
        std::memcpy(&w, p + i, tailBytes - i < 8 ? tailBytes - i : 8);
        h[l] = Step(h[l], w, kPrime[l]);
    }
    const uint64_t a = Fmix(h[0] ^ Rotl(h[2], 23) ^ totalBytes);
    const uint64_t b = Fmix(h[1] ^ Rotl(h[3], 41) ^ (totalBytes * kPrime[0]));
    return {Fmix(a + b), Fmix(b ^ Rotl(a, 32))};
}

Hash128 HashIndexBlock(const void* data, size_t bytes, uint64_t indexBytes) {
    IndexHasher h(indexBytes);
    const size_t whole = bytes & ~size_t(31);
    h.Blocks(data, whole);
    return h.Finish(static_cast<const uint8_t*>(data) + whole, bytes - whole, bytes);
}

// The outer hash's seed: apart from every block's (an element size of 1, 2 or 4).
IndexHashCombiner::IndexHashCombiner(uint64_t indexBytes)
    : outer_(indexBytes ^ 0x6B6C6F6362000000ull), indexBytes_(indexBytes) {}

void IndexHashCombiner::Add(const Hash128& block) {
    if (!hasPending_) {
        pending_[0] = block.lo;
        pending_[1] = block.hi;
        hasPending_ = true;
        return;
    }
    const uint64_t step[4] = {pending_[0], pending_[1], block.lo, block.hi};
    outer_.Blocks(step, sizeof(step));
    hasPending_ = false;
}

void IndexHashCombiner::AddHashes(const void* hashes, size_t count) {
    static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the stored hashes' bytes are the lanes' words");
    const auto* p = static_cast<const uint8_t*>(hashes);
    if (count != 0 && hasPending_) {
        Hash128 first;
        std::memcpy(&first.lo, p, 8);
        std::memcpy(&first.hi, p + 8, 8);
        Add(first);
        p += 16;
        --count;
    }
    outer_.Blocks(p, count / 2 * 32);
    if (count % 2 != 0) {
        std::memcpy(pending_, p + count / 2 * 32, 16);
        hasPending_ = true;
    }
}

void IndexHashCombiner::AddBlocks(const void* data, size_t bytes) {
    const auto* p = static_cast<const uint8_t*>(data);
    const size_t block = IndexHashBlockBytes(indexBytes_);
    for (size_t at = 0; at < bytes; at += block) {
        Add(HashIndexBlock(p + at, bytes - at < block ? bytes - at : block, indexBytes_));
    }
}

Hash128 IndexHashCombiner::Finish(uint64_t totalBytes) {
    return outer_.Finish(pending_, hasPending_ ? sizeof(pending_) : 0, totalBytes);
}

Hash128 HashIndexBytes(const void* data, size_t bytes, uint64_t indexBytes) {
    IndexHashCombiner combiner(indexBytes);
    combiner.AddBlocks(data, bytes);
    return combiner.Finish(bytes);
}

}  // namespace asval::builder
