#include "build_size_cache.h"

#include <cstring>
#include <mutex>

namespace asval {

namespace {

// The signature as a stream of 64-bit words, handed to a sink: hashing, comparing and storing all read the
// app's structures directly, so a lookup needs no buffer of its own.
template <typename Sink>
void EmitSignature(const BuildSignature& s, Sink& sink) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = *s.info;
  // Extension chains are marked (bit 63 and 62), so a signature with one never equals one without: such
  // builds are never stored (Cacheable), and then never found either.
  const uint64_t chained = info.pNext ? uint64_t{1} << 63 : 0;
  sink(chained | (uint64_t{static_cast<uint32_t>(s.build_type)} << 32) | static_cast<uint32_t>(info.type));
  sink((uint64_t{info.flags} << 32) | info.geometryCount);
  // The geometry array and the counts are walked by pointer: Geometry(j) and Count(j) would re-test which
  // array the info uses and multiply the stride for every word.
  const VkAccelerationStructureGeometryKHR* geometries = info.pGeometries;
  const VkAccelerationStructureGeometryKHR* const* geometry_pointers = geometries ? nullptr : info.ppGeometries;
  const char* count = reinterpret_cast<const char*>(s.counts);
  for (uint32_t j = 0; j < info.geometryCount; ++j, count += s.count_stride) {
    const VkAccelerationStructureGeometryKHR* g =
        geometries ? &geometries[j] : geometry_pointers ? geometry_pointers[j] : nullptr;
    if (!g) {
      sink(~uint64_t{0});
      continue;
    }
    const bool data_chained = g->geometryType == VK_GEOMETRY_TYPE_TRIANGLES_KHR && g->geometry.triangles.pNext;
    sink((g->pNext ? uint64_t{1} << 63 : 0) | (data_chained ? uint64_t{1} << 62 : 0) |
         (uint64_t{static_cast<uint32_t>(g->geometryType)} << 32) | g->flags);
    switch (g->geometryType) {
      case VK_GEOMETRY_TYPE_TRIANGLES_KHR: {
        const VkAccelerationStructureGeometryTrianglesDataKHR& t = g->geometry.triangles;
        sink((uint64_t{static_cast<uint32_t>(t.vertexFormat)} << 32) | static_cast<uint32_t>(t.indexType));
        sink(t.vertexStride);
        sink((uint64_t{t.maxVertex} << 1) | (t.transformData.deviceAddress != 0 ? 1u : 0u));
        break;
      }
      case VK_GEOMETRY_TYPE_AABBS_KHR:
        sink(g->geometry.aabbs.stride);
        break;
      case VK_GEOMETRY_TYPE_INSTANCES_KHR:
        sink(g->geometry.instances.arrayOfPointers);
        break;
      default:
        break;  // not cacheable (BuildSignature::Cacheable), never stored
    }
    sink(uint64_t{*reinterpret_cast<const uint32_t*>(count)});
  }
}

// An upper bound of the words EmitSignature hands out: two for the info, at most five per geometry (header,
// three of triangle data, count).
std::size_t MaxSignatureWords(const BuildSignature& s) { return 2 + std::size_t{5} * s.info->geometryCount; }

// One xor and one multiply per word: the word-by-word compare, not the hash, rules out collisions, and Finish
// spreads the high bits the multiply leaves unmixed.
struct HashSink {
  uint64_t h = 0x243f6a8885a308d3ull;
  void operator()(uint64_t w) { h = (h ^ w) * 0x9e3779b97f4a7c15ull; }
};

// Hashes the words and keeps them all for a word-by-word compare; used only when MaxSignatureWords fits, so
// it needs no bound check per word.
struct BufferedSink {
  static constexpr std::size_t kCapacity = 512;  // 4 KiB of stack: infos of up to 102 geometries
  uint64_t words[kCapacity];
  std::size_t count = 0;
  HashSink hash;
  void operator()(uint64_t w) {
    words[count++] = w;
    hash(w);
  }
};

struct CompareSink {
  const std::vector<uint64_t>& words;
  std::size_t next = 0;
  bool equal = true;
  void operator()(uint64_t w) {
    equal = equal && next < words.size() && words[next] == w;
    ++next;
  }
};

struct StoreSink {
  std::vector<uint64_t>& words;
  void operator()(uint64_t w) { words.push_back(w); }
};

// fmix64: spread the last words into the high bits (which pick the shard) and the low ones (the slot of the
// per-thread table).
uint64_t Finish(uint64_t h) {
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdull;
  h ^= h >> 33;
  return h;
}

uint64_t HashOf(const BuildSignature& s) {
  HashSink sink;
  EmitSignature(s, sink);
  return Finish(sink.h);
}

// The per-thread table: direct-mapped, one signature per slot.
struct LocalEntry {
  uint64_t cache_id = 0;  // 0: empty (cache ids start at 1)
  uint64_t hash = 0;
  std::size_t count = 0;
  uint64_t words[BuildSizeCache::kLocalWords];
  BuildSizes sizes;
};
constexpr std::size_t kLocalSlots = 64;

LocalEntry& LocalSlot(uint64_t hash) {
  thread_local LocalEntry table[kLocalSlots];
  return table[hash & (kLocalSlots - 1)];
}

std::atomic<uint64_t> g_next_cache_id{1};

}  // namespace

const VkAccelerationStructureGeometryKHR* BuildSignature::Geometry(uint32_t j) const {
  if (info->pGeometries) return &info->pGeometries[j];
  if (info->ppGeometries) return info->ppGeometries[j];
  return nullptr;
}

bool BuildSignature::Cacheable() const {
  if (info->pNext) return false;
  for (uint32_t j = 0; j < info->geometryCount; ++j) {
    const VkAccelerationStructureGeometryKHR* g = Geometry(j);
    if (!g || g->pNext) return false;
    switch (g->geometryType) {
      case VK_GEOMETRY_TYPE_TRIANGLES_KHR:
        if (g->geometry.triangles.pNext) return false;  // motion vertices, micromaps: sizes depend on them
        break;
      case VK_GEOMETRY_TYPE_AABBS_KHR:
      case VK_GEOMETRY_TYPE_INSTANCES_KHR:
        break;
      default:
        return false;
    }
  }
  return true;
}

BuildSizeCache::BuildSizeCache() : id_(g_next_cache_id.fetch_add(1, std::memory_order_relaxed)) {}

void BuildSizeCache::RememberLocally(uint64_t hash, const uint64_t* words, std::size_t count,
                                     const BuildSizes& sizes) const {
  if (count > kLocalWords) return;
  LocalEntry& slot = LocalSlot(hash);
  slot.cache_id = id_;
  slot.hash = hash;
  slot.count = count;
  std::memcpy(slot.words, words, count * sizeof(uint64_t));
  slot.sizes = sizes;
}

bool BuildSizeCache::Find(const BuildSignature& signature, BuildSizes* out) const {
  if (MaxSignatureWords(signature) > BufferedSink::kCapacity) return FindLong(signature, out);
  // The signature is read from the app's structures once: hashed and kept on the stack for the compares.
  BufferedSink sink;
  EmitSignature(signature, sink);
  const uint64_t hash = Finish(sink.hash.h);
  const bool local = sink.count <= kLocalWords;
  if (local) {
    const LocalEntry& slot = LocalSlot(hash);
    if (slot.cache_id == id_ && slot.hash == hash && slot.count == sink.count &&
        std::memcmp(slot.words, sink.words, sink.count * sizeof(uint64_t)) == 0) {
      *out = slot.sizes;
      return true;
    }
  }
  const Shard& shard = ShardFor(hash);
  {
    std::shared_lock lock(shard.mutex);
    const auto it = shard.map.find(hash);
    if (it == shard.map.end()) return false;
    const std::vector<uint64_t>& stored = it->second.words;
    if (stored.size() != sink.count || std::memcmp(stored.data(), sink.words, sink.count * sizeof(uint64_t)) != 0) {
      return false;
    }
    *out = it->second.sizes;
  }
  if (local) RememberLocally(hash, sink.words, sink.count, *out);
  return true;
}

bool BuildSizeCache::FindLong(const BuildSignature& signature, BuildSizes* out) const {
  // Too long for the stack: hashed in one pass, compared against the stored copy in a second.
  const uint64_t hash = HashOf(signature);
  const Shard& shard = ShardFor(hash);
  std::shared_lock lock(shard.mutex);
  const auto it = shard.map.find(hash);
  if (it == shard.map.end()) return false;
  CompareSink compare{it->second.words};
  EmitSignature(signature, compare);
  if (!compare.equal || compare.next != it->second.words.size()) return false;
  *out = it->second.sizes;
  return true;
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
    heap_counts.resize(info.geometryCount);
    counts = heap_counts.data();
  }
  for (uint32_t j = 0; j < info.geometryCount; ++j) counts[j] = signature.Count(j);

  VkAccelerationStructureBuildSizesInfoKHR answer{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
  query_(device_, signature.build_type, &info, counts, &answer);
  queries_.fetch_add(1, std::memory_order_relaxed);
  const BuildSizes sizes{answer.accelerationStructureSize, answer.buildScratchSize, answer.updateScratchSize};
  if (!signature.Cacheable()) return sizes;

  Entry entry;
  entry.sizes = sizes;
  StoreSink store{entry.words};
  EmitSignature(signature, store);
  const uint64_t hash = HashOf(signature);
  RememberLocally(hash, entry.words.data(), entry.words.size(), sizes);
  Shard& shard = ShardFor(hash);
  std::unique_lock lock(shard.mutex);
  if (shard.map.size() >= kMaxEntriesPerShard) shard.map.clear();
  // A colliding signature (same hash, other words) replaces the old entry: both stay correct, since Find
  // compares the words.
  shard.map.insert_or_assign(hash, std::move(entry));
  return sizes;
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
