// History through device-memory serialization (issue 12) at unit level: the content of captured serialized bytes
// (the header's size, then the hash of exactly that many bytes), and when a deserialization's matching bytes may
// restore its destination's history. The log is made by hand, over host memory, as layer/capture would fill it.
#include <catch2/catch_test_macros.hpp>

#include <cstring>
#include <memory>
#include <vector>

#include "history.h"
#include "history_apply.h"
#include "serialized_capture.h"

namespace asval {
namespace {

constexpr uint64_t kHeaderBytes = 2 * VK_UUID_SIZE + 3 * sizeof(uint64_t);

class HostSlabs : public CaptureSlabOwner {
 public:
  bool Take(VkDeviceSize, CaptureSlab*) override { return false; }
  void Return(const CaptureSlab&) override {}
};

// Captured bytes of `captured` bytes whose header gives `serialized` as the serialized size, the rest a pattern.
struct BlobLog {
  BlobLog(uint64_t serialized, std::size_t captured, uint8_t seed = 1)
      : bytes(captured), log(std::make_shared<CaptureLog>(std::make_shared<HostSlabs>())) {
    for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<uint8_t>(seed + i * 7);
    if (bytes.size() >= kHeaderBytes) std::memcpy(bytes.data() + 2 * VK_UUID_SIZE, &serialized, sizeof(serialized));
    log->slabs.push_back(CaptureSlab{VK_NULL_HANDLE, VK_NULL_HANDLE, bytes.data(), bytes.size()});
    log->AddBlob(CapturedBytes{0, 0, bytes.size(), true});
  }
  std::vector<uint8_t> bytes;
  std::shared_ptr<CaptureLog> log;
};

TEST_CASE("serialization unit: the content is the header's size and the hash of exactly that many bytes",
          "[history][capture]") {
  uint64_t size = 0;
  uint64_t hash = 0;
  BlobLog exact(256, 256);
  REQUIRE(CapturedBlobContent(*exact.log, 0, &size, &hash));
  CHECK(size == 256);
  CHECK(hash == HashBytes(exact.bytes.data(), 256));
  // Bytes after the blob (the rest of a buffer copied up to its end) are not part of it.
  BlobLog longer(256, 1024);
  REQUIRE(CapturedBlobContent(*longer.log, 0, &size, &hash));
  CHECK(size == 256);
  CHECK(hash == HashBytes(longer.bytes.data(), 256));
  // A blob longer than what was copied, a header cut short, a size below the header: unknown, never a prefix.
  CHECK_FALSE(CapturedBlobContent(*BlobLog(512, 256).log, 0, &size, &hash));
  CHECK_FALSE(CapturedBlobContent(*BlobLog(256, kHeaderBytes - 1).log, 0, &size, &hash));
  CHECK_FALSE(CapturedBlobContent(*BlobLog(8, 256).log, 0, &size, &hash));
  CHECK_FALSE(CapturedBlobContent(*exact.log, 1, &size, &hash));  // no such capture
  // Written twice before it was read (a recording pending twice): unknown.
  exact.log->SubmissionStarted();
  exact.log->SubmissionStarted();
  CHECK_FALSE(CapturedBlobContent(*exact.log, 0, &size, &hash));
}

// A destination left unknown by a deserialization of device bytes, with generation `generation`.
AsHistory Deserialized(uint64_t generation) {
  AsHistory h;
  h.kind = HistoryKind::kUnknown;
  h.unknown_reason = UnknownReason::kDeserializedDeviceBytes;
  h.generation = generation;
  return h;
}

TEST_CASE("serialization unit: matching bytes restore the history only of the record the deserialization left",
          "[history][capture]") {
  const auto dst = reinterpret_cast<VkAccelerationStructureKHR>(uintptr_t{0x10});
  auto build = std::make_shared<BuildSnapshot>();
  build->flags = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR;
  HistoryStore store;
  std::unique_lock<std::mutex> lock = store.Lock();
  DeserializeCheck check;
  check.dst = dst;
  check.generation = 7;
  check.build = build;

  SECTION("the same record: restored, generation kept") {
    store.Set(dst, Deserialized(7), nullptr);
    CHECK(RestoreDeserializedHistory(store, check));
    const AsHistory* h = store.Find(dst);
    REQUIRE(h);
    CHECK(h->kind == HistoryKind::kBuilt);
    CHECK(h->build == build);
    CHECK(h->generation == 7);
  }
  SECTION("changed since (an update, a build, another deserialization): not restored") {
    store.Set(dst, Deserialized(8), nullptr);
    CHECK_FALSE(RestoreDeserializedHistory(store, check));
    CHECK(store.Find(dst)->kind == HistoryKind::kUnknown);
  }
  SECTION("written over since (clobbered, the generation unchanged): not restored") {
    AsHistory h = Deserialized(7);
    h.clobbered = Clobber{};
    store.Set(dst, h, nullptr);
    CHECK_FALSE(RestoreDeserializedHistory(store, check));
  }
  SECTION("destroyed since: nothing restored") {
    CHECK_FALSE(RestoreDeserializedHistory(store, check));
    CHECK(store.Find(dst) == nullptr);
  }
}

TEST_CASE("serialization unit: a deserialization restores only when its bytes match a filled serialization",
          "[history][capture]") {
  const auto dst = reinterpret_cast<VkAccelerationStructureKHR>(uintptr_t{0x20});
  HistoryStore store;
  CaptureCounters counters;
  BlobLog written(256, 256);
  BlobLog read_same(256, 512);    // the same bytes, more of the buffer copied
  BlobLog read_other(256, 256, 2);  // other bytes
  auto content = std::make_shared<SerializedContent>();
  SubmissionCaptures serialized;
  serialized.serializes.push_back(SerializeCapture{written.log, 0, content, false});
  CompleteSerializedCaptures(store, counters, serialized);
  REQUIRE(content->status == SerializedContent::Status::kReady);

  const auto run = [&](const BlobLog& read, bool read_twice) {
    {
      std::unique_lock<std::mutex> lock = store.Lock();
      store.Set(dst, Deserialized(3), nullptr);
    }
    SubmissionCaptures done;
    DeserializeCheck check;
    check.log = read.log;
    check.expected = content;
    check.build = std::make_shared<BuildSnapshot>();
    check.dst = dst;
    check.generation = 3;
    check.read_twice = read_twice;
    done.deserializes.push_back(check);
    CompleteSerializedCaptures(store, counters, done);
    std::unique_lock<std::mutex> lock = store.Lock();
    return store.Find(dst)->kind == HistoryKind::kBuilt;
  };
  CHECK_FALSE(run(read_other, false));
  CHECK_FALSE(run(read_same, true));
  CHECK(run(read_same, false));
  CHECK(counters.deserializations_restored.load() == 1);
  CHECK(counters.deserializations_unverified.load() == 2);
  // A serialization whose bytes could not be read leaves its content unknown: nothing matches it.
  auto unknown = std::make_shared<SerializedContent>();
  SubmissionCaptures cut;
  const BlobLog short_read(512, 256);  // named: the log points into its bytes, which must outlive the completion
  cut.serializes.push_back(SerializeCapture{short_read.log, 0, unknown, false});
  CompleteSerializedCaptures(store, counters, cut);
  CHECK(unknown->status == SerializedContent::Status::kUnknown);
}

}  // namespace
}  // namespace asval
