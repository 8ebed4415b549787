// VK_EXT_opacity_micromap in the KHR builds (family "structure"): the
// VkAccelerationStructureTrianglesOpacityMicromapEXT a triangles geometry chains names one array of usage counts
// (pUsageCounts-07335), and an index type (10719) and stride (10722, 10723) the build can read. Through the loader on
// the test driver, which exposes the extension over lavapipe and passes the builds down without it (tests/driver).
#include <catch2/catch_test_macros.hpp>
#include <cstring>

#include "on_test_driver.h"
#include "record_checks_helpers.h"

namespace asval_test {
namespace {

struct MicromapDevice {
  MicromapDevice() {
    options.extensions.push_back(VK_EXT_OPACITY_MICROMAP_EXTENSION_NAME);
    features.micromap = VK_TRUE;
    options.features = &features;
  }
  VkPhysicalDeviceOpacityMicromapFeaturesEXT features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_OPACITY_MICROMAP_FEATURES_EXT};
  vkkit::DeviceOptions options;
};

// One triangle whose opacity comes from `micromap` (its pNext); `micromap` must outlive the build.
struct MicromapTriangle {
  MicromapTriangle(Scene& scene, const VkAccelerationStructureTrianglesOpacityMicromapEXT& m) : micromap(m) {
    geometry = scene.Triangles();
    geometry.geometry.triangles.pNext = &micromap;
    info = Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {geometry});
    info.pGeometries = &geometry;
    info.flags |= VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_OPACITY_MICROMAP_UPDATE_EXT;
    scene.Prepare(info, {1});
  }
  MicromapTriangle(const MicromapTriangle&) = delete;
  VkAccelerationStructureTrianglesOpacityMicromapEXT micromap;
  VkAccelerationStructureGeometryKHR geometry;
  VkAccelerationStructureBuildGeometryInfoKHR info;
};

// An opacity micromap on a buffer of its own (the test driver's object: never built, which the indices below never
// need); destroyed with the object.
class Micromap {
 public:
  explicit Micromap(vkkit::Device& device) : device_(device) {
    storage_ = device.CreateBuffer(4096, VK_BUFFER_USAGE_MICROMAP_STORAGE_BIT_EXT);
    create_ = reinterpret_cast<PFN_vkCreateMicromapEXT>(vkGetDeviceProcAddr(device.handle(), "vkCreateMicromapEXT"));
    destroy_ = reinterpret_cast<PFN_vkDestroyMicromapEXT>(vkGetDeviceProcAddr(device.handle(), "vkDestroyMicromapEXT"));
    VkMicromapCreateInfoEXT info{VK_STRUCTURE_TYPE_MICROMAP_CREATE_INFO_EXT};
    info.buffer = storage_.buffer;
    info.size = storage_.size;
    info.type = VK_MICROMAP_TYPE_OPACITY_MICROMAP_EXT;
    vkkit::Check(create_(device.handle(), &info, nullptr, &handle_), "vkCreateMicromapEXT");
  }
  ~Micromap() {
    destroy_(device_.handle(), handle_, nullptr);
    device_.Destroy(storage_);
  }
  VkMicromapEXT handle() const { return handle_; }

 private:
  vkkit::Device& device_;
  vkkit::Buffer storage_;
  PFN_vkCreateMicromapEXT create_ = nullptr;
  PFN_vkDestroyMicromapEXT destroy_ = nullptr;
  VkMicromapEXT handle_ = VK_NULL_HANDLE;
};

// A triangle's opacity from `micromap`, indexed by special indices only (FULLY_OPAQUE, from `special`), 32-bit, 4
// bytes apart.
VkAccelerationStructureTrianglesOpacityMicromapEXT SpecialIndices(const vkkit::Buffer& special,
                                                                  const Micromap& micromap) {
  VkAccelerationStructureTrianglesOpacityMicromapEXT m{
      VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_TRIANGLES_OPACITY_MICROMAP_EXT};
  m.indexType = VK_INDEX_TYPE_UINT32;
  m.indexBuffer.deviceAddress = special.address;
  m.indexStride = 4;
  m.micromap = micromap.handle();
  return m;
}

vkkit::Buffer SpecialIndexBuffer(vkkit::Device& device) {
  vkkit::Buffer buffer = device.CreateBuffer(256, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
  const uint32_t opaque = static_cast<uint32_t>(VK_OPACITY_MICROMAP_SPECIAL_INDEX_FULLY_OPAQUE_EXT);
  std::memcpy(buffer.mapped, &opaque, sizeof(opaque));
  return buffer;
}

TEST_CASE(
    "micromap: usage counts given twice, an index type the build cannot read, and index strides that are not a "
    "multiple of the index size or beyond 2^32-1 are reported (pUsageCounts-07335, indexType-10719, "
    "indexType-10722, indexType-10723)",
    "[integration][structure][micromap][test-driver][newer-input]") {
  const OnTestDriver driver;
  MicromapDevice micromap_device;
  CheckFixture f("structure", micromap_device.options);
  vkkit::Device& device = f.device();
  Scene scene(device);
  vkkit::Buffer special = SpecialIndexBuffer(device);
  const Micromap micromap(device);
  const VkMicromapUsageEXT usage{0, 1, VK_OPACITY_MICROMAP_FORMAT_2_STATE_EXT};
  const VkMicromapUsageEXT* usage_pointer = &usage;
  VkAccelerationStructureTrianglesOpacityMicromapEXT twice = SpecialIndices(special, micromap);
  twice.usageCountsCount = 1;
  twice.pUsageCounts = &usage;
  twice.ppUsageCounts = &usage_pointer;
  VkAccelerationStructureTrianglesOpacityMicromapEXT uint8 = SpecialIndices(special, micromap);
  uint8.indexType = VK_INDEX_TYPE_UINT8_EXT;
  VkAccelerationStructureTrianglesOpacityMicromapEXT odd = SpecialIndices(special, micromap);
  odd.indexStride = 6;
  VkAccelerationStructureTrianglesOpacityMicromapEXT huge = SpecialIndices(special, micromap);
  huge.indexStride = VkDeviceSize{1} << 32;
  f.monitor().Expect("VUID-VkAccelerationStructureTrianglesOpacityMicromapEXT-pUsageCounts-07335");
  f.monitor().Expect("VUID-VkAccelerationStructureTrianglesOpacityMicromapEXT-indexType-10719");
  f.monitor().Expect("VUID-VkAccelerationStructureTrianglesOpacityMicromapEXT-indexType-10722");
  f.monitor().Expect("VUID-VkAccelerationStructureTrianglesOpacityMicromapEXT-indexType-10723");
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  const VkAccelerationStructureBuildRangeInfoKHR* ranges = &range;
  for (const VkAccelerationStructureTrianglesOpacityMicromapEXT* m : {&twice, &uint8, &odd, &huge}) {
    const MicromapTriangle build(scene, *m);
    device.OneShot([&](VkCommandBuffer cb) { device.CmdBuildAccelerationStructuresKHR(cb, 1, &build.info, &ranges); });
  }
  CHECK(f.monitor().Verify() == "");
  device.Destroy(special);
}

TEST_CASE(
    "micromap valid twin: 32-bit special indices 4 or 8 bytes apart, with usage counts in one array or none, "
    "stay silent and execute",
    "[integration][structure][micromap][test-driver][valid][newer-input]") {
  const OnTestDriver driver;
  MicromapDevice micromap_device;
  CheckFixture f(nullptr, micromap_device.options);
  vkkit::Device& device = f.device();
  Scene scene(device);
  vkkit::Buffer special = SpecialIndexBuffer(device);
  const Micromap micromap(device);
  const VkMicromapUsageEXT usage{0, 1, VK_OPACITY_MICROMAP_FORMAT_2_STATE_EXT};
  VkAccelerationStructureTrianglesOpacityMicromapEXT none = SpecialIndices(special, micromap);
  VkAccelerationStructureTrianglesOpacityMicromapEXT counted = SpecialIndices(special, micromap);
  counted.indexStride = 8;
  counted.usageCountsCount = 1;
  counted.pUsageCounts = &usage;
  const MicromapTriangle a(scene, none), b(scene, counted);
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  scene.BuildNow({a.info, b.info}, {&range, &range});
  CHECK(f.monitor().Verify() == "");
  device.Destroy(special);
}

}  // namespace
}  // namespace asval_test
