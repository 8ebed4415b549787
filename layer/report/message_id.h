#pragma once
// Message ids: the VUID string is pMessageIdName, and its XXH32 hash (seed 8, as the Khronos layer computes
// it) is messageIdNumber, so filters written for the Khronos layer's ids keep working.
#include <cstdint>
#include <string>
#include <string_view>
#include <unordered_set>
#include <vector>

namespace asval {

uint32_t MessageIdHash(std::string_view vuid);

// The mute list (setting message_id_filter). Each entry is a full VUID, a VUID suffix ("03710"), or a message
// id number in decimal or 0x hex. Entries naming an older or newer spelling of a renumbered rule mute every
// spelling, because reports always use the newest name and the filter is expanded through the VUID table.
class MessageFilter {
 public:
  MessageFilter() = default;
  explicit MessageFilter(const std::vector<std::string>& entries);

  // vuid is the newest name, hash its MessageIdHash.
  bool Mutes(std::string_view vuid, uint32_t hash) const;
  bool empty() const { return hashes_.empty() && suffixes_.empty(); }

 private:
  std::unordered_set<uint32_t> hashes_;     // hashes of muted newest names, and raw ids
  std::vector<std::string> suffixes_;       // suffixes that match no VUID in the table (layer-specific ids)
};

}  // namespace asval
