#pragma once
// Per-device cache of what vkGetAccelerationStructureBuildSizesKHR answers for a build.
//
// The size rules (destination size, scratch ranges) and the aliasing rules (the bytes a build really touches)
// need the sizes the driver reports "for an identical VkAccelerationStructureBuildGeometryInfoKHR and
// primitive count". Asking the driver on every recorded build would cost more than the build's recording
// (VVL issue #9428). A steady-state frame records the same builds with the same counts, so the answer is
// cached by the build's signature: everything the sizes depend on (build type, structure type, flags, each
// geometry's type, flags, formats, strides, maxVertex, index type, transform presence, instance layout and
// primitive count), and nothing they do not (addresses, handles, mode: the driver ignores those).
//
// A hit reads the signature once (into a stack buffer, or a per-thread one for infos of more than 102
// geometries), hashes it and compares a stored copy word by word (so a hash collision can never return
// another build's sizes): no allocation, no driver call. A caller that passes its per-thread table first
// compares the app's structures with the words last found for the same arrays, as it reads them (no copy, no
// hash); a difference sends it the long way. A build that is not Cacheable is never stored, and a
// lookup gives up on it as soon as the signature shows it, without hashing. Signatures of up to kLocalWords words (builds of up
// to two geometries) are first looked up in a small per-thread table, which needs no lock at all; the rest,
// and per-thread misses, take one shard's shared lock. A miss of both asks the driver through the next
// layer's dispatch and stores the answer.
//
// Thread safety: Find/Query may run concurrently on any threads; Init runs once at device creation, before
// another thread can see the device.

#include <vulkan/vulkan.h>

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <shared_mutex>
#include <unordered_map>
#include <vector>

#include "geometry_limit.h"

namespace asval {

struct BuildSizes {
  VkDeviceSize acceleration_structure_size = 0;
  VkDeviceSize build_scratch_size = 0;
  VkDeviceSize update_scratch_size = 0;
};

// One build as the size query sees it. The counts are read through a byte stride so that both
// ppBuildRangeInfos[i] (primitiveCount is the first member of VkAccelerationStructureBuildRangeInfoKHR) and
// ppMaxPrimitiveCounts[i] serve without a copy.
struct BuildSignature {
  VkAccelerationStructureBuildTypeKHR build_type = VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR;
  const VkAccelerationStructureBuildGeometryInfoKHR* info = nullptr;
  const uint32_t* counts = nullptr;  // count of geometry j at (const char*)counts + j * count_stride
  std::size_t count_stride = sizeof(uint32_t);

  uint32_t Count(uint32_t j) const {
    return *reinterpret_cast<const uint32_t*>(reinterpret_cast<const char*>(counts) + j * count_stride);
  }
  // Geometry j, whichever of pGeometries / ppGeometries the info uses (null if neither).
  const VkAccelerationStructureGeometryKHR* Geometry(uint32_t j) const;
  // False when an extension structure (a pNext chain, a geometry type the layer does not know) could change the
  // sizes in a way the signature does not capture: such builds are queried every time, never cached.
  bool Cacheable() const;
};

class BuildSizeCache {
 public:
  using QueryFn = PFN_vkGetAccelerationStructureBuildSizesKHR;

  BuildSizeCache();
  BuildSizeCache(const BuildSizeCache&) = delete;
  BuildSizeCache& operator=(const BuildSizeCache&) = delete;

  // The device and the next layer's vkGetAccelerationStructureBuildSizesKHR (null: the cache never queries).
  void Init(VkDevice device, QueryFn query) {
    device_ = device;
    query_ = query;
  }
  bool can_query() const { return query_ != nullptr; }

  // Signatures of at most this many words also live in the per-thread table.
  static constexpr std::size_t kLocalWords = 16;

  // A thread's table of recent hits: direct-mapped, one signature per slot, no lock. A caller that keeps one per
  // thread (the checks' per-thread data) passes it in; the overload without one uses a thread_local table.
  struct ThreadTable {
    struct Entry {
      uint64_t cache_id = 0;  // 0: empty (cache ids start at 1)
      uint64_t hash = 0;
      std::size_t count = 0;
      uint64_t words[kLocalWords];
      BuildSizes sizes;
    };
    static constexpr std::size_t kSlots = 64;
    Entry entries[kSlots];
    Entry& SlotFor(uint64_t hash) { return entries[hash & (kSlots - 1)]; }

    // The signatures last found for an info's geometry and count arrays (a frame records the same builds from
    // the same arrays call after call). Only a hint of where to look: a lookup compares the app's structures
    // with the stored words as it reads them (no copy, no hash), and goes the long way at the first difference.
    struct ByArrays {
      uint64_t cache_id = 0;  // 0: empty
      const void* geometries = nullptr;  // pGeometries or ppGeometries
      const uint32_t* counts = nullptr;
      std::vector<uint64_t> words;  // the signature, padded with zeros; keeps its capacity
      std::size_t count = 0;        // words of the signature
      BuildSizes sizes;
      // The bytes the signature was read from, when the info used pGeometries: its geometry structs as they
      // were, and the counts. An app that records the same arrays unchanged (a frame's builds) is recognized
      // by one memcmp of the structs and a compare of the counts, instead of reading every field the signature
      // takes: equal bytes (with the info's own words equal) give an equal signature, so the answer is the one
      // the word compare would give. Any difference (an address moved) only sends it to the word compare.
      bool raw = false;
      std::vector<VkAccelerationStructureGeometryKHR> raw_geometries;  // keeps its capacity
      std::vector<uint32_t> raw_counts;
    };
    static constexpr std::size_t kArraySlots = 64;
    ByArrays by_arrays[kArraySlots];
    ByArrays& ArraySlotFor(const void* geometries) {
      return by_arrays[(reinterpret_cast<uint64_t>(geometries) * 0x9e3779b97f4a7c15ull) >> 58];
    }
  };

  // The cached sizes of this build, if it was queried before.
  bool Find(const BuildSignature& signature, BuildSizes* out) const;
  bool Find(const BuildSignature& signature, BuildSizes* out, ThreadTable& table) const;

  // Asks the driver and caches the answer (unless !signature.Cacheable()). The caller must have made sure
  // that the query is valid for this info (the layer's own calls must be valid): features enabled, a
  // structurally valid info, counts within the device's limits. The driver is told the handles, mode and
  // addresses are absent (they are ignored by the query anyway), so stale handles never reach it.
  std::optional<BuildSizes> Query(const BuildSignature& signature) const;

  // Driver queries made so far (each lookup that missed and was answered). Hits are lookups minus these.
  uint64_t queries() const { return queries_.load(std::memory_order_relaxed); }
  std::size_t size() const;
  // Forgets every answer (the per-thread tables too). Not concurrent with Find/Query.
  void Clear();

  // A shard holds at most this many signatures; a full shard is emptied (apps whose counts change every
  // frame would otherwise grow the cache without bound).
  static constexpr std::size_t kMaxEntriesPerShard = 1024;

 private:
  struct Entry {
    std::vector<uint64_t> words;  // the full signature, compared on every hit
    BuildSizes sizes;
  };
  struct alignas(64) Shard {
    mutable std::shared_mutex mutex;
    std::unordered_map<uint64_t, Entry> map;  // signature hash -> entry
  };
  static constexpr std::size_t kShardCount = 16;

  Shard& ShardFor(uint64_t hash) const { return shards_[hash >> 60]; }

  // Remembers a signature by its arrays in the calling thread's table.
  // A driver's answer stored in the shared map and this thread's table (may throw std::bad_alloc: Query catches).
  void Remember(const BuildSignature& signature, const BuildSizes& sizes) const;
  void RememberByArrays(ThreadTable& table, const BuildSignature& signature, const uint64_t* words, std::size_t count,
                        const BuildSizes& sizes) const;
  // Stores a hit in the calling thread's table.
  void RememberLocally(ThreadTable& table, uint64_t hash, const uint64_t* words, std::size_t count,
                       const BuildSizes& sizes) const;

  // Names this cache's entries in the per-thread tables; never reused, so an entry of a destroyed device's
  // cache can never answer for another device.
  uint64_t id_;
  VkDevice device_ = VK_NULL_HANDLE;
  QueryFn query_ = nullptr;
  mutable std::array<Shard, kShardCount> shards_;
  mutable std::atomic<uint64_t> queries_{0};
};

}  // namespace asval
