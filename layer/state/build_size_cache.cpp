#include "build_size_cache.h"

#include <algorithm>
#include <cstring>
#include <mutex>
#include <new>

namespace asval {

namespace {

// The signature as 64-bit words, handed one by one to `sink(word)` in order: WriteSignature stores them
// (hashing, comparing and storing all work on these words, read once from the app's structures), and
// MatchesWords compares them with a stored signature as they are read, without storing or hashing them (sink
// returns false at the first difference, which ends the walk). Returns the number of words, or 0 when the walk
// ended early: the build is not cacheable (BuildSignature::Cacheable: an extension chain, a null geometry or a
// geometry type the layer does not know), which shows as soon as the signature does (such a build is never
// stored, so it is never looked up either and pays no hash), or the sink refused a word.
template <typename Sink>
[[gnu::always_inline]] inline std::size_t EmitSignature(const BuildSignature& s, Sink&& sink) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = *s.info;
  if (info.pNext) return 0;
  std::size_t n = 0;
  const auto emit = [&](uint64_t word) {
    ++n;
    return sink(word);
  };
  if (!emit((uint64_t{static_cast<uint32_t>(s.build_type)} << 32) | static_cast<uint32_t>(info.type))) return 0;
  if (!emit((uint64_t{info.flags} << 32) | info.geometryCount)) return 0;
  // The geometry array and the counts are walked by pointer: Geometry(j) and Count(j) would re-test which
  // array the info uses and multiply the stride for every word.
  const VkAccelerationStructureGeometryKHR* geometries = info.pGeometries;
  const VkAccelerationStructureGeometryKHR* const* geometry_pointers = geometries ? nullptr : info.ppGeometries;
  if (info.geometryCount != 0 && !geometries && !geometry_pointers) return 0;
  const char* count = reinterpret_cast<const char*>(s.counts);
  for (uint32_t j = 0; j < info.geometryCount; ++j, count += s.count_stride) {
    const VkAccelerationStructureGeometryKHR* g = geometries ? &geometries[j] : geometry_pointers[j];
    if (!g || g->pNext) return 0;
    if (!emit((uint64_t{static_cast<uint32_t>(g->geometryType)} << 32) | g->flags)) return 0;
    switch (g->geometryType) {
      case VK_GEOMETRY_TYPE_TRIANGLES_KHR: {
        const VkAccelerationStructureGeometryTrianglesDataKHR& t = g->geometry.triangles;
        if (t.pNext) return 0;  // motion vertices, micromaps: the sizes depend on them
        if (!emit((uint64_t{static_cast<uint32_t>(t.vertexFormat)} << 32) | static_cast<uint32_t>(t.indexType)) ||
            !emit(t.vertexStride) ||
            !emit((uint64_t{t.maxVertex} << 1) | (t.transformData.deviceAddress != 0 ? 1u : 0u))) {
          return 0;
        }
        break;
      }
      case VK_GEOMETRY_TYPE_AABBS_KHR:
        if (g->geometry.aabbs.pNext || !emit(g->geometry.aabbs.stride)) return 0;
        break;
      case VK_GEOMETRY_TYPE_INSTANCES_KHR:
        if (g->geometry.instances.pNext || !emit(g->geometry.instances.arrayOfPointers)) return 0;
        break;
      default:
        return 0;
    }
    if (!emit(uint64_t{*reinterpret_cast<const uint32_t*>(count)})) return 0;
  }
  return n;
}

std::size_t WriteSignature(const BuildSignature& s, uint64_t* out) {
  return EmitSignature(s, [&out](uint64_t word) {
    *out++ = word;
    return true;
  });
}

// An upper bound of the words WriteSignature writes: two for the info, at most five per geometry (header,
// three of triangle data, count).
std::size_t MaxSignatureWords(const BuildSignature& s) { return 2 + std::size_t{5} * s.info->geometryCount; }

// Whether the signature of `s` is exactly the `count` words at `words` (and cacheable). `room`: the words that
// may be read there, at least MaxSignatureWords(s) (else no match): the walk then accumulates the differences
// without testing for the end at every word.
bool MatchesWords(const BuildSignature& s, const uint64_t* words, std::size_t count, std::size_t room) {
  if (room < MaxSignatureWords(s)) return false;
  const uint64_t* w = words;
  uint64_t differences = 0;
  const std::size_t n = EmitSignature(s, [&w, &differences](uint64_t word) {
    differences |= *w++ ^ word;
    return true;
  });
  return differences == 0 && n == count;
}

// The signature's first two words, which come from the info alone (EmitSignature writes them first).
uint64_t InfoWord0(const BuildSignature& s) {
  return (uint64_t{static_cast<uint32_t>(s.build_type)} << 32) | static_cast<uint32_t>(s.info->type);
}
uint64_t InfoWord1(const BuildSignature& s) { return (uint64_t{s.info->flags} << 32) | s.info->geometryCount; }

// Whether `s` reads exactly the bytes `slot` last read its signature from (ByArrays::raw): the info's words
// (build type, structure type, flags, geometry count), no info pNext, the geometry structs byte for byte and
// the counts. Then its signature is the slot's (a cacheable one: only such signatures are stored).
constexpr uint32_t kRawCompareFrom = 4;
bool SameBytesAsLast(const BuildSizeCache::ThreadTable::ByArrays& slot, const BuildSignature& s) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = *s.info;
  // A few geometries are compared faster word by word (MatchesWords) than through memcmp's call and setup.
  if (!slot.raw || info.pNext || !info.pGeometries || info.geometryCount < kRawCompareFrom || slot.count < 2) {
    return false;
  }
  if (slot.words[0] != InfoWord0(s) || slot.words[1] != InfoWord1(s)) return false;
  const uint32_t n = info.geometryCount;
  if (slot.raw_geometries.size() != n || slot.raw_counts.size() != n) return false;
  if (n == 0) return true;
  if (std::memcmp(info.pGeometries, slot.raw_geometries.data(), n * sizeof(VkAccelerationStructureGeometryKHR)) != 0) {
    return false;
  }
  uint32_t differences = 0;
  const char* count = reinterpret_cast<const char*>(s.counts);
  for (uint32_t j = 0; j < n; ++j, count += s.count_stride) {
    differences |= slot.raw_counts[j] ^ *reinterpret_cast<const uint32_t*>(count);
  }
  return differences == 0;
}

// Room for one signature: on the stack for infos of up to 102 geometries, else a per-thread buffer that keeps
// its capacity (it grows, once, on the first call of that length on the thread).
class SignatureWords {
 public:
  explicit SignatureWords(const BuildSignature& s) {
    const std::size_t needed = MaxSignatureWords(s);
    words_ = needed <= kStackWords ? stack_ : Spill(needed);
    count_ = WriteSignature(s, words_);
  }
  const uint64_t* data() const { return words_; }
  std::size_t count() const { return count_; }  // 0: not cacheable
  std::size_t bytes() const { return count_ * sizeof(uint64_t); }

 private:
  static constexpr std::size_t kStackWords = 512;  // 4 KiB
  [[gnu::noinline]] static uint64_t* Spill(std::size_t needed) {
    thread_local std::vector<uint64_t> spill;
    if (spill.size() < needed) spill.resize(needed);
    return spill.data();
  }
  uint64_t stack_[kStackWords];
  uint64_t* words_;
  std::size_t count_;
};

// One xor and one multiply per word, then fmix64 to spread the last words into the high bits (which pick the
// shard) and the low ones (the slot of the per-thread table): the word-by-word compare that follows, not the
// hash, rules out collisions. XXH3_64bits over the same words (header-only, SSE2) was measured instead and costs
// more instructions: +15 per lookup of a one-geometry build, +3,900 per lookup of a 256-geometry one
// (docs/performance.md, "One resolved view per build command").
uint64_t HashOf(const SignatureWords& s) {
  uint64_t h = 0x243f6a8885a308d3ull;
  for (const uint64_t* w = s.data(), *end = s.data() + s.count(); w != end; ++w) h = (h ^ *w) * 0x9e3779b97f4a7c15ull;
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdull;
  h ^= h >> 33;
  return h;
}

// The table of callers that keep none of their own (the host family, tests).
BuildSizeCache::ThreadTable& ThisThreadsTable() {
  thread_local BuildSizeCache::ThreadTable table;
  return table;
}

std::atomic<uint64_t> g_next_cache_id{1};

}  // namespace

const VkAccelerationStructureGeometryKHR* BuildSignature::Geometry(uint32_t j) const {
  if (info->pGeometries) return &info->pGeometries[j];
  if (info->ppGeometries) return info->ppGeometries[j];
  return nullptr;
}

bool BuildSignature::Cacheable() const { return SignatureWords(*this).count() != 0; }

BuildSizeCache::BuildSizeCache() : id_(g_next_cache_id.fetch_add(1, std::memory_order_relaxed)) {}

void BuildSizeCache::RememberLocally(ThreadTable& table, uint64_t hash, const uint64_t* words, std::size_t count,
                                     const BuildSizes& sizes) const {
  if (count > kLocalWords) return;
  ThreadTable::Entry& slot = table.SlotFor(hash);
  slot.cache_id = id_;
  slot.hash = hash;
  slot.count = count;
  std::memcpy(slot.words, words, count * sizeof(uint64_t));
  slot.sizes = sizes;
}

bool BuildSizeCache::Find(const BuildSignature& signature, BuildSizes* out) const {
  return Find(signature, out, ThisThreadsTable());
}

// The array an info's geometries are read from (the key of ThreadTable::by_arrays).
const void* GeometryArrayOf(const BuildSignature& s) {
  return s.info->pGeometries ? static_cast<const void*>(s.info->pGeometries) : s.info->ppGeometries;
}

void BuildSizeCache::RememberByArrays(ThreadTable& table, const BuildSignature& signature, const uint64_t* words,
                                      std::size_t count, const BuildSizes& sizes) const {
  ThreadTable::ByArrays& slot = table.ArraySlotFor(GeometryArrayOf(signature));
  // Valid only once complete: an allocation failure below leaves the slot matching nothing.
  slot.cache_id = 0;
  slot.geometries = GeometryArrayOf(signature);
  slot.counts = signature.counts;
  // Padded with zeros to MaxSignatureWords, the room MatchesWords reads; allocates only when this slot meets a
  // longer signature.
  slot.words.assign(words, words + count);
  slot.words.resize(std::max(count, MaxSignatureWords(signature)), 0);
  slot.count = count;
  slot.sizes = sizes;
  const VkAccelerationStructureBuildGeometryInfoKHR& info = *signature.info;
  slot.raw = info.pGeometries != nullptr && info.pNext == nullptr && info.geometryCount >= kRawCompareFrom;
  if (slot.raw) {
    slot.raw_geometries.assign(info.pGeometries, info.pGeometries + info.geometryCount);
    slot.raw_counts.resize(info.geometryCount);
    for (uint32_t j = 0; j < info.geometryCount; ++j) slot.raw_counts[j] = signature.Count(j);
  }
  slot.cache_id = id_;
}

// An allocation failure (a long signature's per-thread room, a memo) is a miss: the caller asks the driver.
bool BuildSizeCache::Find(const BuildSignature& signature, BuildSizes* out, ThreadTable& table) const try {
  const ThreadTable::ByArrays& by_arrays = table.ArraySlotFor(GeometryArrayOf(signature));
  if (by_arrays.cache_id == id_ && by_arrays.geometries == GeometryArrayOf(signature) &&
      by_arrays.counts == signature.counts &&
      ((by_arrays.raw && SameBytesAsLast(by_arrays, signature)) ||  // raw: tested here, before the call
       MatchesWords(signature, by_arrays.words.data(), by_arrays.count, by_arrays.words.size()))) {
    *out = by_arrays.sizes;
    return true;
  }
  const SignatureWords words(signature);
  if (words.count() == 0) return false;  // never stored
  const uint64_t hash = HashOf(words);
  const bool local = words.count() <= kLocalWords;
  if (local) {
    const ThreadTable::Entry& slot = table.SlotFor(hash);
    if (slot.cache_id == id_ && slot.hash == hash && slot.count == words.count() &&
        std::memcmp(slot.words, words.data(), words.bytes()) == 0) {
      *out = slot.sizes;
      RememberByArrays(table, signature, words.data(), words.count(), *out);
      return true;
    }
  }
  const Shard& shard = ShardFor(hash);
  {
    std::shared_lock lock(shard.mutex);
    const auto it = shard.map.find(hash);
    if (it == shard.map.end()) return false;
    const std::vector<uint64_t>& stored = it->second.words;
    if (stored.size() != words.count() || std::memcmp(stored.data(), words.data(), words.bytes()) != 0) {
      return false;
    }
    *out = it->second.sizes;
  }
  if (local) RememberLocally(table, hash, words.data(), words.count(), *out);
  RememberByArrays(table, signature, words.data(), words.count(), *out);
  return true;
} catch (const std::bad_alloc&) {
  return false;
}

std::optional<BuildSizes> BuildSizeCache::Query(const BuildSignature& signature) const {
  if (!query_) return std::nullopt;
  const VkAccelerationStructureBuildGeometryInfoKHR& app_info = *signature.info;
  // Only what the sizes depend on goes down: no handles (one may be stale), no addresses, mode BUILD.
  VkAccelerationStructureBuildGeometryInfoKHR info = app_info;
  info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  info.srcAccelerationStructure = VK_NULL_HANDLE;
  info.dstAccelerationStructure = VK_NULL_HANDLE;
  info.scratchData.deviceAddress = 0;

  constexpr uint32_t kInlineCounts = 64;
  uint32_t inline_counts[kInlineCounts];
  std::vector<uint32_t> heap_counts;  // a miss may allocate; hits never come here
  uint32_t* counts = inline_counts;
  if (info.geometryCount > kInlineCounts) {
    try {
      heap_counts.resize(info.geometryCount);
    } catch (const std::bad_alloc&) {
      return std::nullopt;  // not asked: the rules that need the sizes skip and count
    }
    counts = heap_counts.data();
  }
  for (uint32_t j = 0; j < info.geometryCount; ++j) counts[j] = signature.Count(j);

  VkAccelerationStructureBuildSizesInfoKHR answer{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
  query_(device_, signature.build_type, &info, counts, &answer);
  queries_.fetch_add(1, std::memory_order_relaxed);
  const BuildSizes sizes{answer.accelerationStructureSize, answer.buildScratchSize, answer.updateScratchSize};
  try {
    Remember(signature, sizes);
  } catch (const std::bad_alloc&) {
    // Not cached: the driver's answer still serves this call (and is asked again next time).
  }
  return sizes;
}

void BuildSizeCache::Remember(const BuildSignature& signature, const BuildSizes& sizes) const {
  const SignatureWords words(signature);
  if (words.count() == 0) return;  // not cacheable

  Entry entry;
  entry.sizes = sizes;
  entry.words.assign(words.data(), words.data() + words.count());
  const uint64_t hash = HashOf(words);
  RememberLocally(ThisThreadsTable(), hash, entry.words.data(), entry.words.size(), sizes);
  Shard& shard = ShardFor(hash);
  std::unique_lock lock(shard.mutex);
  if (shard.map.size() >= kMaxEntriesPerShard) shard.map.clear();
  // A colliding signature (same hash, other words) replaces the old entry: both stay correct, since Find
  // compares the words.
  shard.map.insert_or_assign(hash, std::move(entry));
}

std::size_t BuildSizeCache::size() const {
  std::size_t total = 0;
  for (const Shard& shard : shards_) {
    std::shared_lock lock(shard.mutex);
    total += shard.map.size();
  }
  return total;
}

void BuildSizeCache::Clear() {
  id_ = g_next_cache_id.fetch_add(1, std::memory_order_relaxed);  // every per-thread entry is now foreign
  for (Shard& shard : shards_) {
    std::unique_lock lock(shard.mutex);
    shard.map.clear();
  }
}

}  // namespace asval
