// Which devices reduce their captures on the device (capture_method, layer/capture/capture_reducer.h) and gather
// arrays of instance pointers' records, and the layout the host reads a reduced geometry's results in
// (ReducedGeometry, layer/state/capture_log.h).
#include <catch2/catch_test_macros.hpp>

#include <cstring>
#include <vector>

#include "capture_log.h"
#include "capture_reducer.h"

namespace asval {
namespace {

constexpr VkPhysicalDeviceType kGpu = VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU;
constexpr VkPhysicalDeviceType kCpu = VK_PHYSICAL_DEVICE_TYPE_CPU;

TEST_CASE("capture reduce unit: auto reduces on a GPU and copies on a CPU device; reduce and copy are obeyed") {
  CHECK(CaptureReduces(kCaptureMethodAuto, kGpu, true, false, false));
  CHECK(CaptureReduces(kCaptureMethodAuto, VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU, true, false, false));
  CHECK_FALSE(CaptureReduces(kCaptureMethodAuto, kCpu, true, false, false));
  CHECK(CaptureReduces(kCaptureMethodReduce, kCpu, true, false, false));
  CHECK_FALSE(CaptureReduces(kCaptureMethodCopy, kGpu, true, false, false));
}

TEST_CASE("capture reduce unit: never without bufferDeviceAddress, with shader objects or with float_spacing") {
  for (CaptureMethod method : {kCaptureMethodAuto, kCaptureMethodReduce}) {
    CHECK_FALSE(CaptureReduces(method, kGpu, false, false, false));
    CHECK_FALSE(CaptureReduces(method, kGpu, true, true, false));
    CHECK_FALSE(CaptureReduces(method, kGpu, true, false, true));
  }
}

TEST_CASE("capture reduce unit: arrays of instance pointers are gathered wherever the layer may dispatch: any "
          "method on a GPU, reduce on a CPU device; never without bufferDeviceAddress or with shader objects") {
  for (CaptureMethod method : {kCaptureMethodAuto, kCaptureMethodCopy, kCaptureMethodReduce}) {
    CHECK(CaptureGathers(method, kGpu, true, false));
    CHECK(CaptureGathers(method, kCpu, true, false) == (method == kCaptureMethodReduce));
    CHECK_FALSE(CaptureGathers(method, kGpu, false, false));
    CHECK_FALSE(CaptureGathers(method, kGpu, true, true));
  }
}

TEST_CASE("capture reduce unit: which instance pointers the layer follows, and the gathered layout") {
  CHECK_FALSE(FollowedInstancePointer(0));
  CHECK_FALSE(FollowedInstancePointer(0x1008));  // pInfos-03717: never chased
  CHECK_FALSE(FollowedInstancePointer(0x1004));
  CHECK(FollowedInstancePointer(0x1010));
  CHECK(GatheredBytes(3) == 3 * 8 + 3 * 64);
  const uint64_t pointers[2] = {0x2000, 0x2048};
  uint8_t bytes[sizeof(pointers)];
  std::memcpy(bytes, pointers, sizeof(pointers));
  CHECK(InstancePointer(bytes, 1) == 0x2048);
}

TEST_CASE("capture reduce unit: a reduced geometry's bytes, and its bit arrays as the host reads them") {
  // 40 triangles: two words per array, three arrays; indexed: one block of the index hash (16 bytes per 64
  // triangles, whatever the index type); a transform.
  CHECK(ReducedBitBytes(VK_GEOMETRY_TYPE_TRIANGLES_KHR, 40) == 3 * 2 * 4);
  CHECK(ReducedBytes(VK_GEOMETRY_TYPE_TRIANGLES_KHR, 40, true, true) == 24 + 16 + 48);
  CHECK(ReducedBytes(VK_GEOMETRY_TYPE_TRIANGLES_KHR, 1, true, false) == 12 + 16);
  CHECK(ReducedBytes(VK_GEOMETRY_TYPE_TRIANGLES_KHR, 65, true, false) == 3 * 3 * 4 + 2 * 16);  // two blocks
  CHECK(ReducedBytes(VK_GEOMETRY_TYPE_TRIANGLES_KHR, 4096, true, false) == 3 * 128 * 4 + 64 * 16);
  CHECK(ReducedBytes(VK_GEOMETRY_TYPE_TRIANGLES_KHR, 40, false, false) == 24);  // not indexed: no hash
  // 33 instances: 8 bytes of reference each, three arrays of two words, and one summary of 64 records (a 16-byte
  // header and 64 entries of 16 bytes).
  CHECK(ReducedBitBytes(VK_GEOMETRY_TYPE_INSTANCES_KHR, 33) == 33 * 8 + 3 * 2 * 4 + 16 + 64 * 16);

  std::vector<uint8_t> bytes(ReducedBitBytes(VK_GEOMETRY_TYPE_INSTANCES_KHR, 33));
  const uint64_t reference = 0x1234'5678'9abc'de00ull;
  std::memcpy(bytes.data() + 8 * 32, &reference, sizeof(reference));  // instance 32's reference
  const uint32_t active_word1 = 1u;                                    // instance 32 active
  std::memcpy(bytes.data() + 33 * 8 + 4, &active_word1, 4);
  const uint32_t non_finite_word0 = 1u << 5;                           // instance 5's transform
  std::memcpy(bytes.data() + 33 * 8 + 8, &non_finite_word0, 4);
  const ReducedGeometry reduced{bytes.data(), 33, true};
  CHECK(reduced.Word(ReducedGeometry::kActive, 1) == 1u);
  CHECK(reduced.Word(ReducedGeometry::kActive, 0) == 0u);
  CHECK(reduced.Word(ReducedGeometry::kNonFinite, 0) == 1u << 5);
  uint64_t read = 0;
  std::memcpy(&read, reduced.references() + 8 * 32, sizeof(read));
  CHECK(read == reference);
  // The summary of records 0..63: one distinct reference, first held by record 32.
  const uint32_t distinct = 1, first = 32;
  std::memcpy(bytes.data() + 33 * 8 + 24, &distinct, 4);
  std::memcpy(bytes.data() + 33 * 8 + 24 + 16, &reference, 8);
  std::memcpy(bytes.data() + 33 * 8 + 24 + 16 + 8, &first, 4);
  CHECK(reduced.Distinct(0) == 1u);
  uint64_t entry = 0;
  uint32_t entry_first = 0;
  reduced.DistinctReference(0, 0, &entry, &entry_first);
  CHECK(entry == reference);
  CHECK(entry_first == 32u);
}

}  // namespace
}  // namespace asval
