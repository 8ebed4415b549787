// Issue 25, item 6: the capture's copies name only buffers whose lifetime the layer controls. An app may bind two
// buffers over the same memory (a whole-allocation buffer and a view), record a build that reads through one, destroy
// the other and resubmit its prerecorded command buffer: valid for the app (the build reads device addresses that the
// remaining buffer keeps valid). The layer used to copy from the covering buffer with the lowest handle, so its own
// vkCmdCopyBuffer then named a destroyed buffer (the Khronos layer: an invalid command buffer submitted); it now
// copies through a buffer of its own bound to the same memory (layer/capture/memory_aliases.h). These tests stack the
// Khronos validation layer below asval whatever the run (it must report nothing), and check that the capture still
// judges the update after the resubmission (pInfos-03663 fires, its valid twin stays silent).
#include <catch2/catch_test_macros.hpp>

#include <cstdlib>
#include <cstring>
#include <map>
#include <optional>
#include <string>

#include "capture_helpers.h"
#include "capture_skipped.h"
#include "history_helpers.h"
#include "memory_placement_helpers.h"
#include "temp_report.h"
#include "scoped_env.h"

namespace asval_test {
namespace {

constexpr const char* kBecameActive = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03663";
constexpr VkBufferUsageFlags kInputUsage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR;
constexpr uint32_t kVertexOffset = 1024;  // where a test's vertices lie in its memory

using ScopedEnv = ScopedEnvironment;  // scoped_env.h

bool KhronosLayerPresent() {
  uint32_t count = 0;
  vkEnumerateInstanceLayerProperties(&count, nullptr);
  std::vector<VkLayerProperties> layers(count);
  vkEnumerateInstanceLayerProperties(&count, layers.data());
  for (const VkLayerProperties& l : layers) {
    if (std::strcmp(l.layerName, "VK_LAYER_KHRONOS_validation") == 0) return true;
  }
  return false;
}

// The Khronos validation layer below asval for the test's instance (the fixture reads ASVAL_TEST_LAYERS).
class KhronosBelow {
 public:
  KhronosBelow()
      : path_("VK_LAYER_PATH", std::string(std::getenv("VK_LAYER_PATH") ? std::getenv("VK_LAYER_PATH") : "") +
                                   ":/usr/share/vulkan/explicit_layer.d"),
        layers_("ASVAL_TEST_LAYERS", "VK_LAYER_ASVAL_as_validation:VK_LAYER_KHRONOS_validation") {}

 private:
  ScopedEnv path_;
  ScopedEnv layers_;
};

// The Inputs layout's vertices (history_helpers.h: 16, triangles (3k, 3k+1, 3k+2) unit right triangles along z) in
// a buffer the test placed; triangle 1 (vertices 3, 4, 5) active or not: its first vertex's X a number or NaN.
void WriteVertices(const vkkit::Buffer& inputs, VkDeviceSize offset, bool triangle1_active) {
  float vertices[Inputs::kVertexCount * 3];
  for (uint32_t v = 0; v < Inputs::kVertexCount; ++v) {
    const float corner[3][2] = {{0, 0}, {1, 0}, {0, 1}};
    vertices[3 * v + 0] = corner[v % 3][0];
    vertices[3 * v + 1] = corner[v % 3][1];
    vertices[3 * v + 2] = static_cast<float>(v / 3);
  }
  if (!triangle1_active) std::memcpy(&vertices[3 * 3], &kNan, sizeof(kNan));
  std::memcpy(static_cast<char*>(inputs.mapped) + offset, vertices, sizeof(vertices));
}

// A build and an update of a structure from the vertices in `inputs` (a buffer the test placed; its address is the
// geometry's vertexData, the vertices `primitive_offset` bytes into it), recorded once and submitted as often as
// the test wants; triangle 1 inactive in the build when `fire`, active in the update.
class Prerecorded {
 public:
  Prerecorded(vkkit::Device& device, const vkkit::Buffer& inputs, uint32_t primitive_offset = 0)
      : inputs_(inputs), primitive_offset_(primitive_offset), sizing_(device), blas_(device, sizing_),
        procs_(device), commands_(device) {
    build_ = Record(VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
    update_ = Record(VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR);
  }
  void Run(bool fire) {
    WriteVertices(inputs_, primitive_offset_, !fire);
    REQUIRE(commands_.Submit(build_) == VK_SUCCESS);  // waits: the captures are read in the wait
    WriteVertices(inputs_, primitive_offset_, true);
    REQUIRE(commands_.Submit(update_) == VK_SUCCESS);
  }

 private:
  VkCommandBuffer Record(VkBuildAccelerationStructureModeKHR mode) {
    Shape shape;
    shape.triangles = 2;
    shape.primitive_offset = primitive_offset_;
    BuildInfo b = blas_.Info(shape, mode);  // its own Inputs' addresses: read from the placed buffer instead
    for (VkAccelerationStructureGeometryKHR& g : b.geometries) {
      g.geometry.triangles.vertexData.deviceAddress = inputs_.address;
    }
    b.info.pGeometries = b.geometries.data();
    b.range_pointer = b.ranges.data();
    VkCommandBuffer cb = commands_.Begin();
    procs_.CmdBuild(cb, 1, &b.info, &b.range_pointer);
    commands_.End(cb);
    return cb;
  }

  const vkkit::Buffer& inputs_;
  const uint32_t primitive_offset_;
  Inputs sizing_;  // the shapes' sizes (Blas) only: the builds never read it
  Blas blas_;
  Procs procs_;
  Commands commands_;
  VkCommandBuffer build_ = VK_NULL_HANDLE;
  VkCommandBuffer update_ = VK_NULL_HANDLE;
};

TEST_CASE("capture alias: the app destroys the other buffer over its inputs' memory and resubmits; the Khronos layer "
          "below is silent and the update is still judged (pInfos-03663)",
          "[integration][capture][alias]") {
  const KhronosBelow khronos;
  REQUIRE(KhronosLayerPresent());
  for (const bool fire : {true, false}) {
    DYNAMIC_SECTION((fire ? "an update that activates a triangle" : "the valid twin")) {
      HistoryFixture f;  // no settings chain: the Khronos layer 1.3.239 does not know VK_EXT_layer_settings
      vkkit::Device& device = f.device();
      SharedMemory memory(device, 4096);
      // Two buffers over the same bytes: the whole allocation, whose address the build is given (vertexData), and a
      // view of its second KiB, where the vertices lie (primitiveOffset 1024), which the app never uses. The layer
      // used to copy from the covering buffer with the lowest handle: the view, made first (the Khronos layer
      // below hands out handles that count up). The Khronos layer 1.3.239 itself binds the buffers holding a
      // build's vertexData address to the command buffer, so a view holding that address could not be destroyed
      // without its report; this one holds only the bytes the layer copies.
      vkkit::Buffer view = memory.Bind(kVertexOffset, 1024, kInputUsage);
      const vkkit::Buffer whole = memory.Bind(0, 4096, kInputUsage);
      REQUIRE(reinterpret_cast<uintptr_t>(view.buffer) < reinterpret_cast<uintptr_t>(whole.buffer));
      Prerecorded commands(device, whole, kVertexOffset);

      commands.Run(fire);
      if (fire) {
        CHECK(OnlyFinding(f.monitor(), kBecameActive, ": primitive 1") == "");
      } else {
        CHECK(f.monitor().Verify() == "");
      }
      // Valid: nothing the app recorded names the buffer, and the other keeps the addresses valid.
      memory.DestroyBuffer(view);
      commands.Run(fire);
      if (fire) {
        CHECK(OnlyFinding(f.monitor(), kBecameActive, ": primitive 1") == "");
      } else {
        CHECK(f.monitor().Verify() == "");
      }
    }
  }
}

// A dedicated allocation (VkMemoryDedicatedAllocateInfo::buffer) admits no other buffer (VUID-vkBindBufferMemory-
// memory-01508): the layer binds none of its own there and copies from the app's buffer, which it made copyable at
// vkCreateBuffer (the only buffer whose addresses lie there, so no command buffer reading them outlives it).
TEST_CASE("capture alias: inputs in a dedicated allocation are captured from the app's buffer (pInfos-03663), the "
          "Khronos layer below silent",
          "[integration][capture][alias]") {
  const KhronosBelow khronos;
  REQUIRE(KhronosLayerPresent());
  HistoryFixture f;
  vkkit::Device& device = f.device();
  VkBufferCreateInfo create{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  create.size = 1024;
  create.usage = kInputUsage | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
  create.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  vkkit::Buffer placed;
  placed.size = create.size;
  vkkit::Check(vkCreateBuffer(device.handle(), &create, nullptr, &placed.buffer), "vkCreateBuffer");
  VkMemoryRequirements requirements;
  vkGetBufferMemoryRequirements(device.handle(), placed.buffer, &requirements);
  VkMemoryDedicatedAllocateInfo dedicated{VK_STRUCTURE_TYPE_MEMORY_DEDICATED_ALLOCATE_INFO};
  dedicated.buffer = placed.buffer;
  VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO, &dedicated};
  flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  VkMemoryAllocateInfo allocate{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &flags};
  allocate.allocationSize = requirements.size;
  allocate.memoryTypeIndex = device.FindMemoryType(
      requirements.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  vkkit::Check(vkAllocateMemory(device.handle(), &allocate, nullptr, &placed.memory), "vkAllocateMemory");
  vkkit::Check(vkBindBufferMemory(device.handle(), placed.buffer, placed.memory, 0), "vkBindBufferMemory");
  vkkit::Check(vkMapMemory(device.handle(), placed.memory, 0, VK_WHOLE_SIZE, 0, &placed.mapped), "vkMapMemory");
  const VkBufferDeviceAddressInfo address{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO, nullptr, placed.buffer};
  placed.address = vkGetBufferDeviceAddress(device.handle(), &address);
  {
    Prerecorded commands(device, placed);
    commands.Run(true);
    CHECK(OnlyFinding(f.monitor(), kBecameActive, ": primitive 1") == "");
    commands.Run(false);
    CHECK(f.monitor().Verify() == "");
  }
  vkDestroyBuffer(device.handle(), placed.buffer, nullptr);
  vkFreeMemory(device.handle(), placed.memory, nullptr);
}

// Memory exported to other APIs (VkExportMemoryAllocateInfo with handle types) is memory the layer binds no buffer of
// its own to (MemoryState::layer_may_bind), and the app's buffer there is external, which the layer does not make
// copyable: inputs there cannot be copied. The build and its update are not captured, each counted as
// buffer_not_copyable in ASVAL-History-Summary, and the update's activity change is not judged (never a guess).
TEST_CASE("capture alias: inputs in exported memory cannot be copied: not captured, counted as buffer_not_copyable",
          "[integration][capture][alias]") {
  // Reduced on the device, the inputs are read through their device address in place: nothing to copy through.
  if (CaptureReducedRun()) SKIP("capture_method=reduce: the inputs are read in place, captured");
  asval_test_common::TempReport report;
  {
    HistoryFixture f(nullptr, {{"report_file", report.path.c_str()}, {"report_flags", "error,warn,info"}});
    vkkit::Device& device = f.device();
    VkExternalMemoryBufferCreateInfo external{VK_STRUCTURE_TYPE_EXTERNAL_MEMORY_BUFFER_CREATE_INFO};
    external.handleTypes = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
    VkBufferCreateInfo create{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO, &external};
    create.size = 1024;
    create.usage = kInputUsage | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
    create.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    vkkit::Buffer placed;
    placed.size = create.size;
    vkkit::Check(vkCreateBuffer(device.handle(), &create, nullptr, &placed.buffer), "vkCreateBuffer");
    VkMemoryRequirements requirements;
    vkGetBufferMemoryRequirements(device.handle(), placed.buffer, &requirements);
    VkExportMemoryAllocateInfo exported{VK_STRUCTURE_TYPE_EXPORT_MEMORY_ALLOCATE_INFO};
    exported.handleTypes = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
    VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO, &exported};
    flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
    VkMemoryAllocateInfo allocate{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &flags};
    allocate.allocationSize = requirements.size;
    allocate.memoryTypeIndex = device.FindMemoryType(
        requirements.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    vkkit::Check(vkAllocateMemory(device.handle(), &allocate, nullptr, &placed.memory), "vkAllocateMemory");
    vkkit::Check(vkBindBufferMemory(device.handle(), placed.buffer, placed.memory, 0), "vkBindBufferMemory");
    vkkit::Check(vkMapMemory(device.handle(), placed.memory, 0, VK_WHOLE_SIZE, 0, &placed.mapped), "vkMapMemory");
    const VkBufferDeviceAddressInfo address{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO, nullptr, placed.buffer};
    placed.address = vkGetBufferDeviceAddress(device.handle(), &address);
    {
      Prerecorded commands(device, placed);
      commands.Run(true);  // copyable, this would fire pInfos-03663 (the dedicated-allocation test above)
      CHECK(f.monitor().Verify() == "");
    }
    vkDestroyBuffer(device.handle(), placed.buffer, nullptr);
    vkFreeMemory(device.handle(), placed.memory, nullptr);
    f.Close();  // vkDestroyDevice writes the summary
  }
  CHECK(asval_test_common::ReadCaptureSkipped(report.Lines()).NonZero() ==
        std::map<std::string, uint64_t>{{"buffer_not_copyable", 2}});
}

}  // namespace
}  // namespace asval_test
