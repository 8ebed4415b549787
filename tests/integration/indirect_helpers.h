#pragma once
// Indirect builds that execute (on asval's test driver: lavapipe has none), for the integration tests and the
// corpus: a bottom-level structure over inputs the device writes, built and updated by
// vkCmdBuildAccelerationStructuresIndirectKHR from range infos the host writes, and a top-level structure built the
// same way over instances. Each submission is waited for.
#include <vulkan/vulkan.h>

#include <cstring>
#include <functional>
#include <vector>

#include "capture_helpers.h"
#include "history_helpers.h"
#include "vkkit.h"

namespace asval_test {

inline Shape Triangles(uint32_t count = 2) {
  Shape s;
  s.triangles = count;
  return s;
}

inline vkkit::DeviceOptions IndirectBuild() {
  vkkit::DeviceOptions options;
  options.indirect_build = true;
  return options;
}

// A structure over inputs the device writes, built and updated by indirect builds whose range infos (one per
// geometry of the shape) lie in an INDIRECT_BUFFER the test writes from the host before each submission.
class IndirectRig {
 public:
  explicit IndirectRig(vkkit::Device& device)
      : device_(device),
        inputs_(device_, VK_BUFFER_USAGE_TRANSFER_DST_BIT),
        blas_(device_, inputs_),
        commands_(device_),
        ranges_(device_.CreateBuffer(16 * sizeof(VkAccelerationStructureBuildRangeInfoKHR),
                                     VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT)),
        indirect_(reinterpret_cast<PFN_vkCmdBuildAccelerationStructuresIndirectKHR>(
            vkGetDeviceProcAddr(device_.handle(), "vkCmdBuildAccelerationStructuresIndirectKHR"))) {}
  ~IndirectRig() { device_.Destroy(ranges_); }

  vkkit::Device& device() { return device_; }
  Blas& blas() { return blas_; }
  const Inputs& inputs() const { return inputs_; }

  void Write(VkCommandBuffer cb, VkDeviceSize offset, const std::vector<uint32_t>& words) {
    vkCmdUpdateBuffer(cb, inputs_.buffer().buffer, offset, words.size() * sizeof(uint32_t), words.data());
  }
  void Fill(VkCommandBuffer cb, VkDeviceSize offset, uint32_t word) {
    vkCmdFillBuffer(cb, inputs_.buffer().buffer, offset, sizeof(uint32_t), word);
  }

  // The range infos the next indirect build reads, geometry j's at j * 16 (written now: the submission comes later).
  void SetRanges(const std::vector<VkAccelerationStructureBuildRangeInfoKHR>& ranges) {
    std::memcpy(ranges_.mapped, ranges.data(), ranges.size() * sizeof(ranges[0]));
  }

  // One indirect build (or update in place) of the shape's info, the writes recorded before it made visible;
  // `max_count` is every geometry's ppMaxPrimitiveCounts (0: the shape's triangles).
  void Record(VkCommandBuffer cb, const Shape& shape, VkBuildAccelerationStructureModeKHR mode,
              uint32_t max_count = 0) {
    InputsWritten(cb);
    const BuildInfo built = blas_.Info(shape, mode);
    const std::vector<uint32_t> max_counts(built.info.geometryCount, max_count != 0 ? max_count : shape.triangles);
    const uint32_t* counts = max_counts.data();
    const uint32_t stride = sizeof(VkAccelerationStructureBuildRangeInfoKHR);
    indirect_(cb, 1, &built.info, &ranges_.address, &stride, &counts);
  }

  // Records `record` into a new command buffer, submits it and waits for it.
  void Run(const std::function<void(VkCommandBuffer)>& record) {
    SubmitAndWait(device_, RecordWith(commands_, record));
  }

  // A build of the shape with `vertices` written first, its ranges the shape's own.
  void Build(const Shape& shape, const std::vector<uint32_t>& vertices = Vertices()) {
    SetRanges({ShapeRange(shape)});
    Run([&](VkCommandBuffer cb) {
      Write(cb, Component(0, 0), vertices);
      Record(cb, shape, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
    });
  }

  static VkAccelerationStructureBuildRangeInfoKHR ShapeRange(const Shape& shape) {
    return VkAccelerationStructureBuildRangeInfoKHR{shape.triangles, shape.primitive_offset, shape.first_vertex, 0};
  }

 private:
  vkkit::Device& device_;
  Inputs inputs_;
  Blas blas_;
  Commands commands_;
  vkkit::Buffer ranges_;
  PFN_vkCmdBuildAccelerationStructuresIndirectKHR indirect_;
};

// A top-level structure built by indirect builds over instances the test writes from the host.
class IndirectTlas {
 public:
  explicit IndirectTlas(vkkit::Device& device)
      : device_(device),
        tlas_(device),
        commands_(device),
        ranges_(device.CreateBuffer(2 * sizeof(VkAccelerationStructureBuildRangeInfoKHR),
                                    VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT)),
        indirect_(reinterpret_cast<PFN_vkCmdBuildAccelerationStructuresIndirectKHR>(
            vkGetDeviceProcAddr(device.handle(), "vkCmdBuildAccelerationStructuresIndirectKHR"))) {}
  ~IndirectTlas() { device_.Destroy(ranges_); }

  // Builds the top level over `count` of the instances (the range info's count; the recorded maximum is 4), given
  // as records or (`pointers`) as an array of pointers to them.
  // `mode` UPDATE: an update in place of the last build.
  void Build(const vkkit::Buffer& instances, uint32_t count, bool pointers = false,
             VkBuildAccelerationStructureModeKHR mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR) {
    const VkAccelerationStructureBuildRangeInfoKHR range{count, 0, 0, 0};
    std::memcpy(ranges_.mapped, &range, sizeof(range));
    BuildInfo built = tlas_.Info(instances, 4, mode);
    built.geometries[0].geometry.instances.arrayOfPointers = pointers ? VK_TRUE : VK_FALSE;
    const uint32_t max_count = 4;
    const uint32_t* counts = &max_count;
    const uint32_t stride = sizeof(range);
    SubmitAndWait(device_, RecordWith(commands_, [&](VkCommandBuffer cb) {
                    indirect_(cb, 1, &built.info, &ranges_.address, &stride, &counts);
                  }));
  }
  Tlas& tlas() { return tlas_; }

  // One indirect command of two infos: pInfos[0] builds `blas` (one triangle, of at most `bottom_max`), pInfos[1]
  // the top level over `count` of the instances.
  void BuildTogether(const Blas& blas, const vkkit::Buffer& instances, uint32_t count, uint32_t bottom_max = 1) {
    const VkAccelerationStructureBuildRangeInfoKHR ranges[2] = {{1, 0, 0, 0}, {count, 0, 0, 0}};
    std::memcpy(ranges_.mapped, ranges, sizeof(ranges));
    const BuildInfo bottom = blas.Info(Shape{});
    const BuildInfo top = tlas_.Info(instances, 4, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
    const VkAccelerationStructureBuildGeometryInfoKHR infos[2] = {bottom.info, top.info};
    const VkDeviceAddress addresses[2] = {ranges_.address, ranges_.address + sizeof(ranges[0])};
    const uint32_t strides[2] = {sizeof(ranges[0]), sizeof(ranges[0])};
    const uint32_t top_max = 4;
    const uint32_t* counts[2] = {&bottom_max, &top_max};
    SubmitAndWait(device_, RecordWith(commands_, [&](VkCommandBuffer cb) {
                    indirect_(cb, 2, infos, addresses, strides, counts);
                  }));
  }

 private:
  vkkit::Device& device_;
  Tlas tlas_;
  Commands commands_;
  vkkit::Buffer ranges_;
  PFN_vkCmdBuildAccelerationStructuresIndirectKHR indirect_;
};

// What the top-level tests start from: `rig`'s structure built indirectly, `other` over the same inputs built
// directly, and a top-level structure for indirect builds over instances of them
// (`auto& [rig, other, top] = TopLevelRig(device)`).
struct TopLevelRig {
  explicit TopLevelRig(vkkit::Device& device) : rig(device), other(device, rig.inputs()), top(device) {
    rig.Build(Triangles());
    rig.Run([&](VkCommandBuffer cb) { other.Build(cb, Shape{}); });
  }
  IndirectRig rig;
  Blas other;
  IndirectTlas top;
};

}  // namespace asval_test
