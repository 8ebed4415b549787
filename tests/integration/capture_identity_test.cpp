// Execution-time capture of top-level builds: what an instance reference names when addresses are reused, and
// structures whose address the layer learns late or that have none (issue 25, items 1-3).
// - Deferred deletion: engines destroy a structure's buffer while its handle waits for a later deletion pass; a
//   new buffer bound at the same memory offset gets the same address, and so does a new structure created there.
//   A reference to that address names the new, bound structure: never pInfos-03709 against the old handle.
// - A live structure on a buffer without SHADER_DEVICE_ADDRESS usage has no address (no instance can reference it),
//   and a structure created before its buffer had memory gets its address when the buffer is bound: neither turns
//   the reference check (pInfos-06707) off.
// - An instance must reference a bottom-level structure: a reference to a live top-level one is reported.
// The instances are written on the host before each submission; the findings come once the app's wait returned.
#include <catch2/catch_test_macros.hpp>

#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "capture_helpers.h"
#include "history_helpers.h"

namespace asval_test {
namespace {

constexpr const char* kStaleReference = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-06707";
constexpr const char* kStorageNotBound = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03709";

constexpr VkDeviceSize kInstanceBytes = sizeof(VkAccelerationStructureInstanceKHR);  // 64
constexpr uint32_t kSlots = 8;  // structures relocated at once: each had even odds of being taken for its old handle
constexpr VkDeviceSize kOwnStorageBytes = 1 << 20;  // more than lavapipe's size for any Shape

// The messages since the last check, one line each ("id: text"), for a failure's explanation.
std::string Seen(Monitor& monitor) {
  std::string seen;
  for (const Message& m : monitor.Take()) seen += m.id_name + ": " + m.text + "\n";
  return seen;
}

// A bottom-level structure on a buffer and memory of the test's own making: a buffer without
// SHADER_DEVICE_ADDRESS usage, or one the structure is created on before the buffer is bound to memory.
class OwnStructure {
 public:
  OwnStructure(vkkit::Device& device, VkBufferUsageFlags usage) : device_(device) {
    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = kOwnStorageBytes;
    info.usage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR | usage;
    vkkit::Check(vkCreateBuffer(device.handle(), &info, nullptr, &buffer_), "vkCreateBuffer");
    address_bits_ = (usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) != 0;
  }
  ~OwnStructure() {
    if (structure_) device_.DestroyAccelerationStructureKHR(device_.handle(), structure_, nullptr);
    vkDestroyBuffer(device_.handle(), buffer_, nullptr);
    if (memory_) vkFreeMemory(device_.handle(), memory_, nullptr);
  }
  OwnStructure(const OwnStructure&) = delete;
  OwnStructure& operator=(const OwnStructure&) = delete;

  void CreateStructure() {
    VkAccelerationStructureCreateInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
    info.buffer = buffer_;
    info.size = kOwnStorageBytes;
    info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    vkkit::Check(device_.CreateAccelerationStructureKHR(device_.handle(), &info, nullptr, &structure_),
                 "vkCreateAccelerationStructureKHR");
  }
  void Bind() {
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device_.handle(), buffer_, &req);
    VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
    flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, address_bits_ ? &flags : nullptr};
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = device_.FindMemoryType(req.memoryTypeBits, 0);
    vkkit::Check(vkAllocateMemory(device_.handle(), &alloc, nullptr, &memory_), "vkAllocateMemory");
    vkkit::Check(vkBindBufferMemory(device_.handle(), buffer_, memory_, 0), "vkBindBufferMemory");
  }
  // As the app learns it (only for a buffer with SHADER_DEVICE_ADDRESS usage, once bound).
  VkDeviceAddress Address() const {
    VkAccelerationStructureDeviceAddressInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR};
    info.accelerationStructure = structure_;
    return device_.GetAccelerationStructureDeviceAddressKHR(device_.handle(), &info);
  }
  VkAccelerationStructureKHR handle() const { return structure_; }

 private:
  vkkit::Device& device_;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkAccelerationStructureKHR structure_ = VK_NULL_HANDLE;
  bool address_bits_ = false;
};

// Bottom-level structures (`kSlots`, own storage each, built at the start), a `victim` whose handle a probe
// destroys, a top-level structure over up to kSlots instances written on the host, and the command buffers.
class Rig {
 public:
  explicit Rig(HistoryFixture& f)
      : device_(f.device()), procs_(device_), inputs_(device_), victim_(device_, inputs_), tlas_(device_, kSlots),
        commands_(device_) {
    for (uint32_t i = 0; i < kSlots; ++i) blases_.push_back(std::make_unique<Blas>(device_, inputs_));
    instances_ = device_.CreateBuffer(kInstanceBytes * kSlots,
                                      VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
    Run([&](VkCommandBuffer cb) {
      for (auto& blas : blases_) blas->Build(cb, Shape{});
      victim_.Build(cb, Shape{});
    });
  }
  ~Rig() { device_.Destroy(instances_); }
  Rig(const Rig&) = delete;
  Rig& operator=(const Rig&) = delete;

  Blas& blas(uint32_t i) { return *blases_[i]; }
  Blas& victim() { return victim_; }
  Tlas& tlas() { return tlas_; }
  vkkit::Device& device() { return device_; }

  void Run(const std::function<void(VkCommandBuffer)>& record) { SubmitAndWait(device_, RecordWith(commands_, record)); }

  // A top-level build (in a command buffer of its own) whose instances reference `references`, in this order.
  void BuildTopLevel(const std::vector<VkDeviceAddress>& references) {
    std::vector<VkAccelerationStructureInstanceKHR> instances;
    for (uint32_t i = 0; i < references.size(); ++i) instances.push_back(InstanceRecord(references[i], i));
    std::memcpy(instances_.mapped, instances.data(), instances.size() * kInstanceBytes);
    Run([&](VkCommandBuffer cb) {
      tlas_.Record(cb, instances_, static_cast<uint32_t>(references.size()), VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
    });
  }

  // A build of `dst` from the inputs a Blas builds from (its scratch borrowed).
  void BuildInto(VkCommandBuffer cb, VkAccelerationStructureKHR dst) {
    BuildInfo b = victim_.Info(Shape{});
    b.info.dstAccelerationStructure = dst;
    procs_.CmdBuild(cb, 1, &b.info, &b.range_pointer);
  }

  // Whether the reference check is live: an instance referencing the victim's old address (its handle destroyed
  // now, its storage kept: lavapipe still reads bytes there) must be reported. A valid twin's silence only means
  // something if its references were judged (a check skipped for unknown state is silent too).
  std::string ProbeReferences(Monitor& monitor) {
    victim_.DestroyHandle();
    BuildTopLevel({blas(0).address(), victim_.address()});
    const std::vector<Message> messages = monitor.Take();
    const std::string expected = "instance 1 references 0x";
    if (messages.size() == 1 && messages[0].id_name == kStaleReference &&
        messages[0].text.find(expected) != std::string::npos) {
      return "";
    }
    std::string seen = "expected one " + std::string(kStaleReference) + " naming '" + expected + "', saw:\n";
    for (const Message& m : messages) seen += m.id_name + ": " + m.text + "\n";
    return seen;
  }

 private:
  vkkit::Device& device_;
  Procs procs_;
  Inputs inputs_;
  std::vector<std::unique_ptr<Blas>> blases_;
  Blas victim_;
  Tlas tlas_;
  Commands commands_;
  vkkit::Buffer instances_;
};

TEST_CASE("capture valid twin: deferred deletion, new structures at the addresses of structures whose buffers were "
          "destroyed and whose handles wait for a deletion pass, referenced by a top-level build, stay silent",
          "[integration][capture]") {
  HistoryFixture f;
  Rig rig(f);
  // Frame N: every structure's buffer is destroyed, its handle kept for the deletion pass; a new buffer at the same
  // memory offset and a new structure there, built, and a top-level build referencing the new ones only.
  std::vector<VkAccelerationStructureKHR> waiting;
  std::vector<VkDeviceAddress> references;
  for (uint32_t i = 0; i < kSlots; ++i) {
    const VkDeviceAddress before = rig.blas(i).address();
    waiting.push_back(rig.blas(i).Relocate());
    REQUIRE(rig.blas(i).address() == before);  // the new structure took the old one's address
    references.push_back(before);
  }
  rig.Run([&](VkCommandBuffer cb) {
    for (uint32_t i = 0; i < kSlots; ++i) rig.blas(i).Build(cb, Shape{});
  });
  rig.BuildTopLevel(references);
  CHECK(Seen(f.monitor()) == "");
  // Frame N+2: the deletion pass destroys the old handles; the same top-level build again.
  for (VkAccelerationStructureKHR old : waiting) {
    rig.device().DestroyAccelerationStructureKHR(rig.device().handle(), old, nullptr);
  }
  rig.BuildTopLevel(references);
  CHECK(Seen(f.monitor()) == "");
  CHECK(rig.ProbeReferences(f.monitor()) == "");
}

TEST_CASE("capture: a reference to the address of a structure whose buffer was destroyed is still reported when no "
          "live structure took the address (pInfos-03709)",
          "[integration][capture][passes-invalid-down]") {
  HistoryFixture f;
  Rig rig(f);
  // Slot 0 is relocated and its new structure destroyed at once: only the old handle, on a destroyed buffer, has
  // the address (its memory stays: lavapipe reads the old bytes). Slot 1 is relocated and built validly.
  const VkAccelerationStructureKHR old0 = rig.blas(0).Relocate();
  rig.blas(0).DestroyHandle();
  const VkAccelerationStructureKHR old1 = rig.blas(1).Relocate();
  rig.Run([&](VkCommandBuffer cb) { rig.blas(1).Build(cb, Shape{}); });
  rig.BuildTopLevel({rig.blas(1).address(), rig.blas(0).address()});
  const std::vector<Message> messages = f.monitor().Take();
  REQUIRE(messages.size() == 1);
  CHECK(messages[0].id_name == kStorageNotBound);
  CHECK(messages[0].text.find("instance 1 references VkAccelerationStructureKHR") != std::string::npos);
  REQUIRE(messages[0].objects.size() == 3);
  CHECK(messages[0].objects[2].objectHandle == reinterpret_cast<uint64_t>(old0));
  rig.device().DestroyAccelerationStructureKHR(rig.device().handle(), old0, nullptr);
  rig.device().DestroyAccelerationStructureKHR(rig.device().handle(), old1, nullptr);
}

TEST_CASE("capture: a live structure on a buffer without SHADER_DEVICE_ADDRESS usage leaves stale references "
          "reported (pInfos-06707)",
          "[integration][capture]") {
  HistoryFixture f;
  Rig rig(f);
  // Bound through descriptors only: it has no address, so no instance can reference it.
  OwnStructure no_address(rig.device(), 0);
  no_address.Bind();
  no_address.CreateStructure();
  rig.BuildTopLevel({rig.blas(0).address(), rig.blas(1).address()});
  CHECK(Seen(f.monitor()) == "");
  CHECK(rig.ProbeReferences(f.monitor()) == "");
}

TEST_CASE("capture valid twin: a structure created before its buffer had memory gets its address when the buffer is "
          "bound: referenced, it stays silent, and stale references are still reported (pInfos-06707)",
          "[integration][capture]") {
  HistoryFixture f;
  Rig rig(f);
  OwnStructure late(rig.device(), VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT);
  late.CreateStructure();  // valid: the buffer must be bound before the structure is used, not before it is created
  late.Bind();
  rig.Run([&](VkCommandBuffer cb) { rig.BuildInto(cb, late.handle()); });
  rig.BuildTopLevel({late.Address(), rig.blas(0).address()});
  CHECK(Seen(f.monitor()) == "");
  CHECK(rig.ProbeReferences(f.monitor()) == "");
}

TEST_CASE("capture: an instance referencing a top-level structure is reported (pInfos-06707)",
          "[integration][capture][passes-invalid-down]") {
  HistoryFixture f;
  Rig rig(f);
  // An inner top-level structure over blas 0, built validly; the outer one references it beside blas 1.
  Tlas inner(rig.device(), 1);
  vkkit::Buffer inner_instances = inner.MakeInstances({&rig.blas(0)});
  rig.Run([&](VkCommandBuffer cb) {
    inner.Record(cb, inner_instances, 1, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
  });
  CHECK(Seen(f.monitor()) == "");
  VkAccelerationStructureDeviceAddressInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR};
  info.accelerationStructure = inner.handle();
  const VkDeviceAddress inner_address =
      rig.device().GetAccelerationStructureDeviceAddressKHR(rig.device().handle(), &info);
  rig.BuildTopLevel({rig.blas(1).address(), inner_address});
  const std::vector<Message> messages = f.monitor().Take();
  REQUIRE(messages.size() == 1);
  CHECK(messages[0].id_name == kStaleReference);
  CHECK(messages[0].text.find("geometry 0: 1 instance(s) reference a top-level acceleration structure") !=
        std::string::npos);
  CHECK(messages[0].text.find("instance 1 references VkAccelerationStructureKHR") != std::string::npos);
  rig.device().Destroy(inner_instances);
}

}  // namespace
}  // namespace asval_test
