#pragma once
// The buffers recent build commands have looked up. A recorded build reads many ranges of the same few
// buffers: one vertex buffer for many geometries, one scratch buffer sliced per info, one storage buffer
// holding many structures; a frame records the same buffers call after call. The memo keeps up to kEntries
// buffers found (their address range, usage and memory binding), so each is looked up in the shared maps
// (locks, hashing) once rather than once per range. One memo per thread, kept from call to call: Sync, at
// the start of each call, empties it unless the device's buffer map and address map are the very ones it
// was filled from and have not changed since (their change stamps), so it never serves a stale record.
// Entries are found through two direct-mapped indexes, by the start address a lookup asked for and by
// handle, so a call over many buffers (16 infos with a scratch and a vertex buffer each, and their
// destinations' buffers) finds each in a few instructions, without a scan and without evicting the others;
// a memo that fills up starts over.
#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <utility>

#include "device_state.h"

namespace asval {

struct KnownBuffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  uint64_t id = 0;  // BufferState::id: which buffer of that handle value
  VkDeviceAddress base = 0;  // device address range [base, base + size); size 0: the buffer has none
  VkDeviceSize size = 0;
  VkBufferUsageFlags usage = 0;
  bool bound = false;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkDeviceSize memory_offset = 0;

  bool Holds(VkDeviceAddress address, VkDeviceSize bytes) const {
    return size != 0 && address >= base && address - base <= size && bytes <= size - (address - base);
  }
};

class BufferMemo {
 public:
  // A bound buffer whose address range holds all of [address, address + bytes) (bytes 0: just `address`) and
  // that was created with every bit of `usage`; false when none does.
  bool Holding(const DeviceState& state, VkDeviceAddress address, VkDeviceSize bytes, VkBufferUsageFlags usage,
               KnownBuffer* out) {
    const KnownBuffer* held = Held(state, address, bytes, usage);
    if (!held) return false;
    *out = *held;
    return true;
  }
  // The same without copying the record out: the entry stays valid until the memo's next lookup. The two
  // entries that answered last are tried first, inline (the geometries of a call mostly read one vertex
  // buffer; its infos alternate between that and one scratch buffer).
  const KnownBuffer* Held(const DeviceState& state, VkDeviceAddress address, VkDeviceSize bytes,
                          VkBufferUsageFlags usage) {
    const KnownBuffer& last = entries_[last_];  // an empty entry (size 0) holds nothing
    if (Serves(last, address, bytes, usage)) return &last;
    const KnownBuffer& before = entries_[before_];
    if (Serves(before, address, bytes, usage)) {
      std::swap(last_, before_);
      return &before;
    }
    return HeldSlow(state, address, bytes, usage);
  }
  // Whether `hint` names a filled entry. The bound of the array too, though count_ never exceeds it: g++ 14 cannot
  // see that and warns (-Warray-bounds) where a caller's hint is a constant past the array.
  bool Fresh(uint8_t hint) const { return hint < count_ && hint < entries_.size(); }
  // Holding and FindOfStructure for a lookup that recurs from call to call at the same place (pInfos[i]'s
  // scratch, its destination's buffer): `hint` is the entry that answered it last (any value at first), tried
  // before everything else and updated. Any entry that serves is a right answer (every entry is valid for the
  // maps as they are), so a stale hint only costs the usual lookup.
  [[gnu::always_inline]] bool HoldingHinted(const DeviceState& state, VkDeviceAddress address, VkDeviceSize bytes,
                                            VkBufferUsageFlags usage, uint8_t& hint, KnownBuffer* out) {
    if (Fresh(hint) && Serves(entries_[hint], address, bytes, usage)) {
      *out = entries_[hint];
      return true;
    }
    const KnownBuffer* held = Held(state, address, bytes, usage);
    if (!held) return false;
    hint = static_cast<uint8_t>(held - entries_.data());
    *out = *held;
    return true;
  }
  bool FindOfStructureHinted(const DeviceState& state, const AccelerationStructureState& structure, uint8_t& hint,
                             KnownBuffer* out) {
    if (Fresh(hint) && entries_[hint].buffer == structure.buffer) {
      *out = entries_[hint];
      return out->id == structure.buffer_id;
    }
    if (!Find(state, structure.buffer, out)) return false;
    hint = last_found_;
    return out->id == structure.buffer_id;
  }

  // Empties the memo unless it was filled from these very maps, unchanged since. Call before any lookup of a
  // command.
  void Sync(const DeviceState& state) {
    const StampValue buffers = state.buffers.stamp();
    const StampValue addresses = state.buffer_addresses.stamp();
    if (buffers == buffers_stamp_ && addresses == addresses_stamp_) return;
    buffers_stamp_ = buffers;
    addresses_stamp_ = addresses;
    Reset();
  }
  // The record of `buffer`; false when the layer does not know the buffer.
  bool Find(const DeviceState& state, VkBuffer buffer, KnownBuffer* out);
  // The buffer `structure` was created on; false when it is unknown or was destroyed (even if a new buffer
  // now has its handle value: structure_memory.h).
  bool FindOfStructure(const DeviceState& state, const AccelerationStructureState& structure, KnownBuffer* out) {
    return Find(state, structure.buffer, out) && out->id == structure.buffer_id;
  }

 private:
  static constexpr int kEntries = 128;
  static constexpr unsigned kSlots = 256;  // per index; a slot holds entry + 1 (0: empty)
  static_assert(kEntries < 256, "slots hold entry indexes in a byte");
  static unsigned SlotOf(uint64_t key) { return static_cast<unsigned>((key * 0x9e3779b97f4a7c15ull) >> 56); }
  static bool Serves(const KnownBuffer& e, VkDeviceAddress address, VkDeviceSize bytes, VkBufferUsageFlags usage) {
    return (e.usage & usage) == usage && e.Holds(address, bytes == 0 ? 1 : bytes);
  }
  const KnownBuffer* HeldSlow(const DeviceState& state, VkDeviceAddress address, VkDeviceSize bytes,
                              VkBufferUsageFlags usage);
  // Makes `entry` the answer Held gives first and returns it.
  const KnownBuffer* Answer(int entry) {
    before_ = last_;
    last_ = entry;
    return &entries_[entry];
  }
  // Stores an entry (starting over when full); returns its index.
  int Remember(const KnownBuffer& entry);
  void Reset();

  std::array<KnownBuffer, kEntries> entries_{};
  int count_ = 0;
  uint8_t last_found_ = 0;  // the entry Find answered from last
  int last_ = 0;    // the entry Held returned last
  int before_ = 0;  // and the one before it
  std::array<uint64_t, kSlots> address_keys_{};  // the start address a lookup asked for
  std::array<uint8_t, kSlots> address_entries_{};
  std::array<uint64_t, kSlots> handle_keys_{};
  std::array<uint8_t, kSlots> handle_entries_{};
  StampValue buffers_stamp_;    // the maps the entries come from, as they were (id 0: none yet)
  StampValue addresses_stamp_;
};

}  // namespace asval
