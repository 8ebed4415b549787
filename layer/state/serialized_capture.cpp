#include "serialized_capture.h"

#include <cstring>

#include "history.h"
#include "history_apply.h"

namespace asval {

namespace {

// The serialized header: the driver UUID and the compatibility UUID, then the total serialized size, the
// deserialized size and the count of handles that follow (VkCmdCopyAccelerationStructureToMemoryKHR).
constexpr uint64_t kSizeOffset = 2 * VK_UUID_SIZE;
constexpr uint64_t kHeaderBytes = 2 * VK_UUID_SIZE + 3 * sizeof(uint64_t);

}  // namespace

bool CapturedBlobContent(const CaptureLog& log, uint32_t blob, uint64_t* size, uint64_t* hash) {
  const CapturedBytes* bytes = log.ReadableBlob(blob);
  if (!bytes || bytes->size < kHeaderBytes) return false;
  const uint8_t* data = log.Bytes(*bytes);
  uint64_t serialized = 0;
  std::memcpy(&serialized, data + kSizeOffset, sizeof(serialized));
  // A size that does not fit what was copied (a blob larger than the budget or the buffer allowed, or bytes that
  // are not a serialization at all) is not hashed: a prefix would match blobs that differ after it.
  if (serialized < kHeaderBytes || serialized > bytes->size) return false;
  *size = serialized;
  *hash = HashBytes(data, static_cast<std::size_t>(serialized));
  return true;
}

void CompleteSerializedCaptures(HistoryStore& store, CaptureCounters& counters, SubmissionCaptures& done) {
  for (SerializeCapture& s : done.serializes) {
    SerializedContent& content = *s.content;
    if (content.status != SerializedContent::Status::kPending) continue;
    const bool known = !s.read_twice && CapturedBlobContent(*s.log, s.blob, &content.size, &content.hash);
    content.status = known ? SerializedContent::Status::kReady : SerializedContent::Status::kUnknown;
  }
  for (const DeserializeCheck& d : done.deserializes) {
    uint64_t size = 0;
    uint64_t hash = 0;
    const bool match = !d.read_twice && d.expected && d.expected->status == SerializedContent::Status::kReady &&
                       CapturedBlobContent(*d.log, d.blob, &size, &hash) && size == d.expected->size &&
                       hash == d.expected->hash;
    bool restored = false;
    if (match) {
      std::unique_lock<std::mutex> lock = store.Lock();
      restored = RestoreDeserializedHistory(store, d);
    }
    (restored ? counters.deserializations_restored : counters.deserializations_unverified)
        .fetch_add(1, std::memory_order_relaxed);
  }
}

}  // namespace asval
