#include "message_id.h"

#define XXH_INLINE_ALL
#include <xxhash.h>

#include <cerrno>
#include <cstdlib>

#include "vuid_table.h"

namespace asval {

uint32_t MessageIdHash(std::string_view vuid) { return XXH32(vuid.data(), vuid.size(), 8); }

namespace {

bool EndsWith(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

// A suffix matches at a '-' boundary: "03710" matches "...-pInfos-03710" but not "...-103710".
bool MatchesSuffix(std::string_view vuid, std::string_view suffix) {
  if (vuid == suffix) return true;
  return EndsWith(vuid, suffix) && vuid.size() > suffix.size() && vuid[vuid.size() - suffix.size() - 1] == '-';
}

bool ParseNumber(const std::string& s, uint32_t* out) {
  if (s.empty()) return false;
  errno = 0;
  char* end = nullptr;
  const unsigned long long v = std::strtoull(s.c_str(), &end, 0);
  if (errno != 0 || *end != '\0' || v > 0xffffffffull) return false;
  *out = static_cast<uint32_t>(v);
  return true;
}

}  // namespace

MessageFilter::MessageFilter(const std::vector<std::string>& entries) {
  for (const std::string& entry : entries) {
    if (entry.empty()) continue;
    // A bare number of 5 digits is a VUID suffix, as in the Khronos layer; longer numbers and 0x are ids.
    uint32_t id = 0;
    const bool looks_like_suffix = entry.size() <= 5 && entry.find_first_not_of("0123456789") == std::string::npos;
    if (!looks_like_suffix && ParseNumber(entry, &id)) {
      hashes_.insert(id);
      continue;
    }
    bool matched = false;
    for (size_t i = 0; i < VuidCount(); ++i) {
      const VuidInfo* info = VuidAt(i);
      if (entry == info->vuid || MatchesSuffix(info->vuid, entry)) {
        hashes_.insert(MessageIdHash(info->newest));
        matched = true;
      }
    }
    if (!matched) {
      // Not in the spec table: a layer-specific id (e.g. "ASVAL-..."), matched by name or suffix at report time.
      hashes_.insert(MessageIdHash(entry));
      suffixes_.push_back(entry);
    }
  }
}

bool MessageFilter::Mutes(std::string_view vuid, uint32_t hash) const {
  if (hashes_.count(hash)) return true;
  for (const std::string& s : suffixes_) {
    if (MatchesSuffix(vuid, s)) return true;
  }
  return false;
}

}  // namespace asval
