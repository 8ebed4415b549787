// History through device-memory serialization (execution-time capture, issue 12): the layer copies the bytes a
// vkCmdCopyAccelerationStructureToMemoryKHR wrote (after it) and those a vkCmdCopyMemoryToAccelerationStructureKHR
// reads (before it), hashes both once their submissions completed, and gives the deserialized structure the
// serialized one's history (last build and primitive activity) only when they match. Until that completion is
// processed, and whenever the bytes differ, the history stays unknown: the update rules are skipped and counted,
// never guessed. Without the capture (before issue 12) every deserialization of device bytes left the history
// unknown, so the invalid updates below went unreported: the first two tests fail on that behaviour.

#include <catch2/catch_test_macros.hpp>
#include <cstdio>

#include "capture_helpers.h"
#include "history_helpers.h"
#include "temp_report.h"

namespace asval_test {
namespace {

constexpr const char* kPrimitiveCount = "VUID-vkCmdBuildAccelerationStructuresKHR-primitiveCount-03769";
constexpr const char* kBecameInactive = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03664";

// One triangle, with maxVertex room for two: an update to two triangles then changes only primitiveCount.
Shape OneTriangle() {
  Shape s;
  s.max_vertex = 5;
  return s;
}
Shape TwoTriangles() {
  Shape s = OneTriangle();
  s.triangles = 2;
  return s;
}

// The serialized bytes land in, and are read from, a buffer the app may copy (TRANSFER_SRC): the layer adds no
// usage to such buffers (no usage names a serialization buffer), so it copies only from buffers the app made
// copyable.
constexpr VkBufferUsageFlags kBlobUsage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;

// The serialized bytes written (a serialization, a fill or a copy into them) made visible to a deserialization.
void BlobWritten(VkCommandBuffer cb) {
  VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;
  barrier.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                       VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, 0, 1, &barrier, 0, nullptr, 0, nullptr);
}

// An original structure built with `shape`, serialized into a device buffer of exactly its serialization size
// (read back with a query, as apps do), and a structure to deserialize it into. Every submission is waited for
// (vkQueueWaitIdle: the layer processes the captures of what completed there).
class Rig {
 public:
  explicit Rig(HistoryFixture& f, const Shape& shape)
      : device_(f.device()), inputs_(device_, VK_BUFFER_USAGE_TRANSFER_DST_BIT), original_(device_, inputs_),
        restored_(device_, inputs_), commands_(device_) {
    QueryPool pool(device_, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR, 1);
    VkCommandBuffer cb = commands_.Begin();
    pool.Reset(cb);
    original_.Build(cb, shape);
    commands_.Barrier(cb);
    CmdWriteProperties(device_, cb, {original_.handle()}, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR,
                       pool.handle(), 0);
    commands_.End(cb);
    REQUIRE(commands_.Submit(cb) == VK_SUCCESS);
    size_ = pool.Results()[0];
    REQUIRE(size_ > 0);
    blob_ = device_.CreateBuffer(size_, kBlobUsage);
  }
  ~Rig() { device_.Destroy(blob_); }

  vkkit::Device& device() { return device_; }
  Inputs& inputs() { return inputs_; }
  Blas& restored() { return restored_; }
  Commands& commands() { return commands_; }
  const vkkit::Buffer& blob() const { return blob_; }

  void Serialize(VkCommandBuffer cb) { CmdSerialize(device_, cb, original_.handle(), blob_.address); }
  void Deserialize(VkCommandBuffer cb) { CmdDeserialize(device_, cb, blob_.address, restored_.handle()); }
  // A command buffer of its own, submitted and waited for.
  VkResult Run(const std::function<void(VkCommandBuffer)>& record) {
    VkCommandBuffer cb = commands_.Begin();
    record(cb);
    commands_.End(cb);
    return commands_.Submit(cb);
  }

 private:
  vkkit::Device& device_;
  Inputs inputs_;
  Blas original_, restored_;
  Commands commands_;
  uint64_t size_ = 0;
  vkkit::Buffer blob_;
};

TEST_CASE("capture: a structure deserialized from device bytes the layer saw serialized keeps the original's "
          "history (primitiveCount-03769 on its update)",
          "[integration][capture][history]") {
  HistoryFixture f("history");
  Rig rig(f, OneTriangle());
  REQUIRE(rig.Run([&](VkCommandBuffer cb) { rig.Serialize(cb); }) == VK_SUCCESS);
  REQUIRE(rig.Run([&](VkCommandBuffer cb) { rig.Deserialize(cb); }) == VK_SUCCESS);
  // The deserialization's completion was processed in that wait: the update is judged against the original's build.
  f.monitor().Expect(kPrimitiveCount);
  CHECK(rig.Run([&](VkCommandBuffer cb) { rig.restored().Update(cb, TwoTriangles()); }) ==
        VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(f.monitor().Verify() == "");
}

// The behaviour before issue 12, kept with the capture off: the same flow as the test above, whose update is then
// not judged. This is what the test above fails on without the capture of serialized bytes.
TEST_CASE("capture off: a structure deserialized from device bytes has an unknown history (its invalid update is "
          "not judged)",
          "[integration][capture][history][passes-invalid-down]") {
  HistoryFixture f("history", {{"capture", "off"}});
  Rig rig(f, OneTriangle());
  REQUIRE(rig.Run([&](VkCommandBuffer cb) { rig.Serialize(cb); }) == VK_SUCCESS);
  REQUIRE(rig.Run([&](VkCommandBuffer cb) { rig.Deserialize(cb); }) == VK_SUCCESS);
  CHECK(rig.Run([&](VkCommandBuffer cb) { rig.restored().Update(cb, TwoTriangles()); }) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("capture: a structure deserialized from device bytes keeps the original's primitive activity "
          "(pInfos-03664 on its update)",
          "[integration][capture][history][passes-invalid-down]") {
  HistoryFixture f;
  Rig rig(f, TwoTriangles());
  REQUIRE(rig.Run([&](VkCommandBuffer cb) {
            rig.Serialize(cb);
            BlobWritten(cb);
            rig.Deserialize(cb);  // the same command buffer: the serialization's content is filled first
          }) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
  // The update's inputs make triangle 0 inactive (a NaN X); the original built it active. Reported when the
  // update's submission completes (the bytes are known only then), so the update itself reaches the driver.
  CHECK(rig.Run([&](VkCommandBuffer cb) {
          vkCmdFillBuffer(cb, rig.inputs().buffer().buffer, Inputs::kVerticesOffset, sizeof(uint32_t), kNan);
          InputsWritten(cb);
          rig.restored().Update(cb, TwoTriangles());
        }) == VK_SUCCESS);
  CHECK(OnlyFinding(f.monitor(), kBecameInactive, ": primitive 0") == "");
}

TEST_CASE("capture valid twin: updates of a structure deserialized from device bytes that repeat the original's "
          "build stay silent",
          "[integration][capture][history]") {
  HistoryFixture f;
  Rig rig(f, OneTriangle());
  SECTION("serialized and deserialized in separate submissions") {
    REQUIRE(rig.Run([&](VkCommandBuffer cb) { rig.Serialize(cb); }) == VK_SUCCESS);
    REQUIRE(rig.Run([&](VkCommandBuffer cb) { rig.Deserialize(cb); }) == VK_SUCCESS);
  }
  SECTION("serialized and deserialized in one command buffer") {
    REQUIRE(rig.Run([&](VkCommandBuffer cb) {
              rig.Serialize(cb);
              BlobWritten(cb);
              rig.Deserialize(cb);
            }) == VK_SUCCESS);
  }
  CHECK(rig.Run([&](VkCommandBuffer cb) { rig.restored().Update(cb, OneTriangle()); }) == VK_SUCCESS);
  CHECK(rig.Run([&](VkCommandBuffer cb) { rig.restored().Update(cb, OneTriangle()); }) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
}

// The summary vkDestroyDevice writes, after `scenario` ran on a fresh device.
std::string Summary(const std::function<void(HistoryFixture&)>& scenario) {
  asval_test_common::TempReport report;
  {
    HistoryFixture f("history", {{"report_file", report.path.c_str()}, {"report_flags", "error,warn,info"}});
    scenario(f);
    f.Close();
  }
  std::string json;
  for (const std::string& line : report.Lines()) json += line + "\n";
  return json;
}

TEST_CASE("capture: device bytes rewritten between the serialization and the deserialization leave the history "
          "unknown (the invalid update is skipped and counted)",
          "[integration][capture][history][passes-invalid-down]") {
  const std::string json = Summary([](HistoryFixture& f) {
    Rig rig(f, OneTriangle());
    REQUIRE(rig.Run([&](VkCommandBuffer cb) { rig.Serialize(cb); }) == VK_SUCCESS);
    REQUIRE(rig.Run([&](VkCommandBuffer cb) {
              // One word of the blob rewritten by a command the layer does not follow. The driver UUID: lavapipe's
              // deserialization does not read it, so the structure stays what was serialized, and only the
              // layer's verification by content can tell the bytes changed.
              vkCmdFillBuffer(cb, rig.blob().buffer, 0, sizeof(uint32_t), 0xdeadbeefu);
              BlobWritten(cb);
              rig.Deserialize(cb);
            }) == VK_SUCCESS);
    // Invalid against the original's build, but the history is unknown: not judged.
    CHECK(rig.Run([&](VkCommandBuffer cb) { rig.restored().Update(cb, TwoTriangles()); }) == VK_SUCCESS);
    CHECK(f.monitor().Verify() == "");
  });
  CHECK(json.find("serialized bytes captured 2 times") != std::string::npos);
  CHECK(json.find("0 deserializations of device bytes restored their history") != std::string::npos);
  CHECK(json.find("1 left it unknown") != std::string::npos);
  CHECK(json.find("history checks were skipped because the history they need was unknown") != std::string::npos);
}

TEST_CASE("capture: an update submitted with the deserialization, before its completion was processed, is "
          "skipped and counted, and the later restore does not overwrite it",
          "[integration][capture][history][passes-invalid-down]") {
  const std::string json = Summary([](HistoryFixture& f) {
    Rig rig(f, OneTriangle());
    REQUIRE(rig.Run([&](VkCommandBuffer cb) { rig.Serialize(cb); }) == VK_SUCCESS);
    // One submission: at submission the deserialized history is unknown (the bytes are verified at completion),
    // so the update, invalid against the original's build, is not judged.
    CHECK(rig.Run([&](VkCommandBuffer cb) {
            rig.Deserialize(cb);
            rig.commands().Barrier(cb);
            rig.restored().Update(cb, TwoTriangles());
          }) == VK_SUCCESS);
    CHECK(f.monitor().Verify() == "");
    // The update's record stands (two triangles): the completion did not restore the original's over it, so an
    // update back to one triangle is the one reported.
    CHECK(rig.Run([&](VkCommandBuffer cb) { rig.restored().Update(cb, TwoTriangles()); }) == VK_SUCCESS);
    CHECK(f.monitor().Verify() == "");
    f.monitor().Expect(kPrimitiveCount);
    CHECK(rig.Run([&](VkCommandBuffer cb) { rig.restored().Update(cb, OneTriangle()); }) ==
          VK_ERROR_VALIDATION_FAILED_EXT);
    CHECK(f.monitor().Verify() == "");
  });
  CHECK(json.find("0 deserializations of device bytes restored their history") != std::string::npos);
  CHECK(json.find("1 left it unknown") != std::string::npos);
  CHECK(json.find("history checks were skipped because the history they need was unknown") != std::string::npos);
}

// Issue 25, item 6: the blob is copied through the layer's own buffer over the memory (layer/capture/
// memory_aliases.h), so a serialization buffer needs no usage of its own (it used to need the app's TRANSFER_SRC,
// and such bytes were left unknown).
TEST_CASE("capture: bytes deserialized from a buffer without TRANSFER_SRC are captured through the layer's buffer "
          "over its memory, and the history comes back (primitiveCount-03769)",
          "[integration][capture][history]") {
  const std::string json = Summary([](HistoryFixture& f) {
    vkkit::Device& device = f.device();
    Inputs inputs(device);
    Blas original(device, inputs), restored(device, inputs);
    Commands commands(device);
    vkkit::Buffer blob = device.CreateBuffer(1 << 20, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    VkCommandBuffer cb = commands.Begin();
    original.Build(cb, OneTriangle());
    commands.Barrier(cb);
    CmdSerialize(device, cb, original.handle(), blob.address);
    BlobWritten(cb);
    CmdDeserialize(device, cb, blob.address, restored.handle());
    commands.End(cb);
    REQUIRE(commands.Submit(cb) == VK_SUCCESS);
    CHECK(f.monitor().Verify() == "");
    // The restored structure's last build is the original's (one triangle): an update with two is reported.
    f.monitor().Expect(kPrimitiveCount);
    CHECK(commands.Submit(RecordWith(commands, [&](VkCommandBuffer u) { restored.Update(u, TwoTriangles()); })) ==
          VK_ERROR_VALIDATION_FAILED_EXT);
    CHECK(f.monitor().Verify() == "");
    device.Destroy(blob);
  });
  CHECK(json.find("serialized bytes captured 2 times (serializations and deserializations), not captured 0 "
                  "times") != std::string::npos);
  CHECK(json.find("1 deserializations of device bytes restored their history") != std::string::npos);
}

}  // namespace
}  // namespace asval_test
