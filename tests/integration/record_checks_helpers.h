#pragma once
// Helpers for the tests of the record-time build rules (families features, handles, structure, alignment):
// a fixture whose enabled_checks can be narrowed to the family under test, the three build commands behind
// one call, and a scene of valid build inputs (triangles, indexed triangles, AABBs, instances) in one
// host-visible buffer, with destinations and scratch sized by the driver so that valid twins really run.
#include <memory>
#include <string>
#include <vector>

#include "fixture.h"

namespace asval_test {

// A Fixture whose enabled_checks setting names only `families` (e.g. "structure"), or all families when
// null. Negative tests narrow it, so that another family's rule about the same deliberately broken input
// does not add its own finding; valid twins keep every family on.
class CheckFixture {
 public:
  explicit CheckFixture(const char* families = nullptr, const vkkit::DeviceOptions& device = {});
  Monitor& monitor() { return fixture_->monitor(); }
  vkkit::Instance& instance() { return fixture_->instance(); }
  vkkit::Device& device() { return fixture_->device(); }

 private:
  ApiSettings settings_;
  std::unique_ptr<Fixture> fixture_;
};

enum class Command { kDirect, kIndirect, kHost };
constexpr Command kAllCommands[] = {Command::kDirect, Command::kIndirect, Command::kHost};
const char* CommandName(Command command);

// One rule's VUID for each of the three commands, spelled out (the registry looks for the literal names).
struct PerCommand {
  const char* direct;
  const char* indirect;
  const char* host;
  const char* For(Command command) const;
};

// Records (device commands; never submitted) or calls (host) one build of `infos`. Indirect builds get
// 4-aligned placeholder addresses, stride 16 and the range counts as ppMaxPrimitiveCounts; host builds no
// deferred operation. Lavapipe has neither indirect nor host builds: only calls the layer skips (an expected
// finding) may go through those two.
struct IndirectArgs {
  VkDeviceAddress address = 0x10000;
  uint32_t stride = 16;
};
void Issue(vkkit::Device& device, Command command, const std::vector<VkAccelerationStructureBuildGeometryInfoKHR>& infos,
           const std::vector<const VkAccelerationStructureBuildRangeInfoKHR*>& ranges, IndirectArgs indirect = {});
// One info, one geometry per entry of `ranges` (or none).
void IssueOne(vkkit::Device& device, Command command, const VkAccelerationStructureBuildGeometryInfoKHR& info,
              const VkAccelerationStructureBuildRangeInfoKHR* ranges);

// Valid build inputs in one host-visible buffer, plus a built bottom-level structure that the instance
// record points at. Everything the scene creates is destroyed with it.
class Scene {
 public:
  // Offsets of the inputs in `inputs` (all aligned as the rules want; tests add small offsets to break them).
  static constexpr VkDeviceSize kVertices = 0;        // 3 vertices of R32G32B32_SFLOAT, stride 12
  static constexpr VkDeviceSize kWideVertices = 256;  // the same 3 vertices in 44-byte interleaved records
  static constexpr VkDeviceSize kIndices32 = 512;     // 0, 1, 2 as uint32
  static constexpr VkDeviceSize kIndices16 = 578;     // 0, 1, 2 as uint16 (2-aligned, not 4-aligned)
  static constexpr VkDeviceSize kTransforms = 640;    // two identity VkTransformMatrixKHR, 48 bytes apart
  static constexpr VkDeviceSize kAabbs = 768;         // two VkAabbPositionsKHR, stride 24
  static constexpr VkDeviceSize kInstances = 1024;    // two VkAccelerationStructureInstanceKHR of the scene's BLAS
  static constexpr VkDeviceSize kPointers = 1280;     // two pointers to those instances
  static constexpr VkDeviceSize kSize = 4096;

  explicit Scene(vkkit::Device& device);
  ~Scene();
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  VkDeviceAddress Address(VkDeviceSize offset) const { return inputs_.address + offset; }

  // Geometries over the inputs (device addresses).
  VkAccelerationStructureGeometryKHR Triangles() const;
  VkAccelerationStructureGeometryKHR IndexedTriangles(VkIndexType type) const;
  VkAccelerationStructureGeometryKHR Aabbs() const;
  VkAccelerationStructureGeometryKHR Instances(bool array_of_pointers = false) const;

  // A BUILD-mode info of `type` over `geometries` (pGeometries), flags PREFER_FAST_TRACE | ALLOW_UPDATE.
  static VkAccelerationStructureBuildGeometryInfoKHR Info(VkAccelerationStructureTypeKHR type,
                                                         const std::vector<VkAccelerationStructureGeometryKHR>& geometries);

  // Gives `info` a destination created with `created_type` (the info's type by default) and the size the
  // driver asks for these counts, and a scratch slice of that build's size (128-byte aligned, one buffer for
  // every Prepare of the scene).
  void Prepare(VkAccelerationStructureBuildGeometryInfoKHR& info, const std::vector<uint32_t>& counts,
               VkAccelerationStructureTypeKHR created_type = VK_ACCELERATION_STRUCTURE_TYPE_MAX_ENUM_KHR);
  // A structure of the scene's own (destroyed with the scene).
  VkAccelerationStructureKHR NewStructure(VkAccelerationStructureTypeKHR type, VkDeviceSize size);
  // Records the build, submits it and waits: valid twins run for real on the driver.
  void BuildNow(const std::vector<VkAccelerationStructureBuildGeometryInfoKHR>& infos,
                const std::vector<const VkAccelerationStructureBuildRangeInfoKHR*>& ranges);

  VkAccelerationStructureKHR blas() const { return blas_.handle; }

  // The same geometry with host addresses (the scene's buffer is mapped): for host builds whose checks read
  // the data (the largest index of maxVertex-10774).
  VkAccelerationStructureGeometryKHR OnHost(VkAccelerationStructureGeometryKHR geometry) const;

 private:
  vkkit::Device& device_;
  vkkit::Buffer inputs_;
  vkkit::Buffer scratch_;
  VkDeviceSize scratch_used_ = 0;
  vkkit::AccelerationStructure blas_;
  std::vector<vkkit::AccelerationStructure> structures_;
};

// Ranges of `count` primitives at offset 0 for each of `geometries` geometries.
std::vector<VkAccelerationStructureBuildRangeInfoKHR> Ranges(size_t geometries, uint32_t count = 1);

// The first queue family of `gpu` with compute.
uint32_t ComputeQueueFamily(VkPhysicalDevice gpu);

// A device with VK_KHR_acceleration_structure enabled but not its accelerationStructure feature (an app that forgot
// the feature structure): a valid device on which no build may be recorded. One primary command buffer, begun.
class FeaturelessDevice {
 public:
  explicit FeaturelessDevice(VkPhysicalDevice gpu);
  ~FeaturelessDevice();
  FeaturelessDevice(const FeaturelessDevice&) = delete;
  FeaturelessDevice& operator=(const FeaturelessDevice&) = delete;
  VkCommandBuffer cb() const { return cb_; }
  PFN_vkCmdBuildAccelerationStructuresKHR CmdBuild = nullptr;

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer cb_ = VK_NULL_HANDLE;
};

}  // namespace asval_test
