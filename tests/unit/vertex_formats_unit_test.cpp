// The shared vertex-format table (asval/vertex_formats.h) against values written out by hand from the
// specification (formats chapter: texel sizes, packed formats, numeric formats; the acceleration-structure
// chapter: the vertexFormat / vertexStride-03735 / primitiveOffset-03657 / pInfos-03711 wording), never from
// the traits the table is computed from.
#include <catch2/catch_test_macros.hpp>

#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "asval/builder/vertex_format.h"
#include "asval/vertex_formats.h"
#include "build_sizes.h"
#include "build_state_fixture.h"

namespace asval {
namespace {

struct Expected {
  VkFormat format;
  ComponentKind kind;
  uint8_t bits;        // of X
  uint8_t count;       // components
  uint8_t vertex;      // bytes per vertex (texel size)
  uint8_t unit;        // alignment unit: component size, or the packed size
  bool packed;
  bool nan;            // X can be NaN
  bool mandatory;      // formats.adoc: ACCELERATION_STRUCTURE_VERTEX_BUFFER_BIT_KHR is mandatory
};

// Every format the layer accepts as an acceleration-structure vertex format: the six mandatory ones, the
// optional formats of the same families, and A2B10G10R10_UNORM_PACK32 (packed: its unit is 4 bytes).
constexpr Expected kExpected[] = {
    {VK_FORMAT_R32G32_SFLOAT, ComponentKind::Float32, 32, 2, 8, 4, false, true, true},
    {VK_FORMAT_R32G32B32_SFLOAT, ComponentKind::Float32, 32, 3, 12, 4, false, true, true},
    {VK_FORMAT_R32G32B32A32_SFLOAT, ComponentKind::Float32, 32, 4, 16, 4, false, true, false},
    {VK_FORMAT_R16G16_SFLOAT, ComponentKind::Float16, 16, 2, 4, 2, false, true, true},
    {VK_FORMAT_R16G16B16_SFLOAT, ComponentKind::Float16, 16, 3, 6, 2, false, true, false},
    {VK_FORMAT_R16G16B16A16_SFLOAT, ComponentKind::Float16, 16, 4, 8, 2, false, true, true},
    {VK_FORMAT_R16G16_SNORM, ComponentKind::Snorm, 16, 2, 4, 2, false, false, true},
    {VK_FORMAT_R16G16B16_SNORM, ComponentKind::Snorm, 16, 3, 6, 2, false, false, false},
    {VK_FORMAT_R16G16B16A16_SNORM, ComponentKind::Snorm, 16, 4, 8, 2, false, false, true},
    {VK_FORMAT_R16G16_UNORM, ComponentKind::Unorm, 16, 2, 4, 2, false, false, false},
    {VK_FORMAT_R16G16B16_UNORM, ComponentKind::Unorm, 16, 3, 6, 2, false, false, false},
    {VK_FORMAT_R16G16B16A16_UNORM, ComponentKind::Unorm, 16, 4, 8, 2, false, false, false},
    {VK_FORMAT_R8G8_SNORM, ComponentKind::Snorm, 8, 2, 2, 1, false, false, false},
    {VK_FORMAT_R8G8B8_SNORM, ComponentKind::Snorm, 8, 3, 3, 1, false, false, false},
    {VK_FORMAT_R8G8B8A8_SNORM, ComponentKind::Snorm, 8, 4, 4, 1, false, false, false},
    {VK_FORMAT_R8G8_UNORM, ComponentKind::Unorm, 8, 2, 2, 1, false, false, false},
    {VK_FORMAT_R8G8B8_UNORM, ComponentKind::Unorm, 8, 3, 3, 1, false, false, false},
    {VK_FORMAT_R8G8B8A8_UNORM, ComponentKind::Unorm, 8, 4, 4, 1, false, false, false},
    {VK_FORMAT_A2B10G10R10_UNORM_PACK32, ComponentKind::Unorm1010102, 10, 4, 4, 4, true, false, false},
};

TEST_CASE("vertex formats: every acceleration-structure vertex format has its hand-written facts", "[unit][formats]") {
  for (const Expected& e : kExpected) {
    INFO("format " << e.format);
    const VertexFormatInfo& f = VertexFormatFacts(e.format);
    CHECK(f.format == e.format);
    CHECK(f.decodable);
    CHECK(f.kind == e.kind);
    CHECK(f.componentBits == e.bits);
    CHECK(f.componentCount == e.count);
    CHECK(f.vertexBytes == e.vertex);
    CHECK(f.componentBytes == e.unit);
    CHECK(f.packed == e.packed);
    CHECK(f.hasNaN == e.nan);
    CHECK(f.mandatory == e.mandatory);
    // The builder's lookup answers from the same row.
    const VertexFormatInfo* found = builder::FindVertexFormat(e.format);
    REQUIRE(found != nullptr);
    CHECK(found->format == e.format);
    CHECK(found->vertexBytes == e.vertex);
  }
}

TEST_CASE("vertex formats: the decodable list is exactly the expected formats, once each", "[unit][formats]") {
  std::set<VkFormat> expected;
  for (const Expected& e : kExpected) expected.insert(e.format);
  std::set<VkFormat> listed;
  for (const VertexFormatInfo* f = DecodableVertexFormatsBegin(); f != DecodableVertexFormatsEnd(); ++f) {
    CHECK(listed.insert(f->format).second);
    CHECK(f->decodable);
  }
  CHECK(listed == expected);
  CHECK(builder::VertexFormatsEnd() - builder::VertexFormatsBegin() == 19);
}

TEST_CASE("vertex formats: alignment facts of other colour formats, and formats the table does not describe",
          "[unit][formats]") {
  struct Unit {
    VkFormat format;
    uint8_t vertex;
    uint8_t unit;
    bool packed;
    bool nan;
  };
  // One or two from each run of the core enum (vulkan_core.h lays core formats out by component size).
  const Unit units[] = {
      {VK_FORMAT_R4G4_UNORM_PACK8, 1, 1, true, false},
      {VK_FORMAT_R4G4B4A4_UNORM_PACK16, 2, 2, true, false},
      {VK_FORMAT_R5G6B5_UNORM_PACK16, 2, 2, true, false},
      {VK_FORMAT_A1R5G5B5_UNORM_PACK16, 2, 2, true, false},
      {VK_FORMAT_R8_UNORM, 1, 1, false, false},
      {VK_FORMAT_B8G8R8A8_SRGB, 4, 1, false, false},
      {VK_FORMAT_A8B8G8R8_UNORM_PACK32, 4, 4, true, false},
      {VK_FORMAT_A2R10G10B10_UNORM_PACK32, 4, 4, true, false},
      {VK_FORMAT_A2B10G10R10_SINT_PACK32, 4, 4, true, false},
      {VK_FORMAT_R16_UNORM, 2, 2, false, false},
      {VK_FORMAT_R16_SFLOAT, 2, 2, false, true},
      {VK_FORMAT_R32_UINT, 4, 4, false, false},
      {VK_FORMAT_R32G32B32A32_SINT, 16, 4, false, false},
      {VK_FORMAT_R64_UINT, 8, 8, false, false},
      {VK_FORMAT_R64G64B64_SFLOAT, 24, 8, false, true},
      {VK_FORMAT_R64G64B64A64_SFLOAT, 32, 8, false, true},
      {VK_FORMAT_B10G11R11_UFLOAT_PACK32, 4, 4, true, true},
      {VK_FORMAT_E5B9G9R9_UFLOAT_PACK32, 4, 4, true, true},
      // Extension formats outside the indexed range.
      {VK_FORMAT_A4R4G4B4_UNORM_PACK16, 2, 2, true, false},
      {VK_FORMAT_A4B4G4R4_UNORM_PACK16, 2, 2, true, false},
      {VK_FORMAT_R16G16_S10_5_NV, 4, 2, false, false},
  };
  for (const Unit& u : units) {
    INFO("format " << u.format);
    const VertexFormatInfo& f = VertexFormatFacts(u.format);
    CHECK(f.vertexBytes == u.vertex);
    CHECK(f.componentBytes == u.unit);
    CHECK(f.packed == u.packed);
    CHECK(f.hasNaN == u.nan);
    CHECK_FALSE(f.decodable);
    CHECK(builder::FindVertexFormat(u.format) == nullptr);
  }
  // Depth, compressed, multi-planar, undefined and unknown values: nothing described, nothing decodable.
  const VkFormat undescribed[] = {VK_FORMAT_UNDEFINED,
                                  VK_FORMAT_D16_UNORM,
                                  VK_FORMAT_D32_SFLOAT,
                                  VK_FORMAT_D24_UNORM_S8_UINT,
                                  VK_FORMAT_BC1_RGB_UNORM_BLOCK,
                                  VK_FORMAT_ASTC_12x12_SRGB_BLOCK,
                                  VK_FORMAT_G8_B8R8_2PLANE_420_UNORM,
                                  VK_FORMAT_R10X6_UNORM_PACK16,
                                  static_cast<VkFormat>(1000470000),
                                  static_cast<VkFormat>(0x7FFFFFFF)};
  for (VkFormat format : undescribed) {
    INFO("format " << format);
    const VertexFormatInfo& f = VertexFormatFacts(format);
    CHECK(f.vertexBytes == 0);
    CHECK(f.componentBytes == 0);
    CHECK_FALSE(f.packed);
    CHECK_FALSE(f.decodable);
  }
}

// What the checks make of the table. The address and size families used to keep their own lists, which
// missed the 3-component 8/16-bit formats and A2B10G10R10_UNORM_PACK32; these fail with those lists.

constexpr VkBufferUsageFlags kInput = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR;
constexpr VkAccelerationStructureTypeKHR kBottom = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;

// A device that supports every format as an acceleration-structure vertex format.
VKAPI_ATTR void VKAPI_CALL EveryFormatIsAVertexFormat(VkPhysicalDevice, VkFormat, VkFormatProperties* properties) {
  *properties = VkFormatProperties{};
  properties->bufferFeatures = VK_FORMAT_FEATURE_ACCELERATION_STRUCTURE_VERTEX_BUFFER_BIT_KHR;
}

void SupportEveryFormat(BuildStateFixture& f) {
  f.state.format_features.Init(reinterpret_cast<VkPhysicalDevice>(uintptr_t{0x2}), &EveryFormatIsAVertexFormat);
}

BuildSignature Signature(const VkAccelerationStructureBuildGeometryInfoKHR& info, const uint32_t* counts) {
  return BuildSignature{VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &info, counts, sizeof(uint32_t)};
}

TEST_CASE("vertex formats: the layer asks the size query about every vertex format the device supports",
          "[unit][formats][sizes]") {
  for (const Expected& e : kExpected) {
    INFO("format " << e.format);
    BuildStateFixture f;
    SupportEveryFormat(f);
    VkAccelerationStructureGeometryKHR g = TriangleGeometry(0x1000);
    g.geometry.triangles.vertexFormat = e.format;
    g.geometry.triangles.vertexStride = e.vertex;
    const VkAccelerationStructureBuildGeometryInfoKHR info = OneGeometryInfo(kBottom, &g);
    const uint32_t counts[1] = {1};
    CHECK(SizeQueryIsValid(f.state, Signature(info, counts)));
    if (e.unit > 1) {
      // vertexStride-03735: a stride off the unit would make the query itself invalid.
      g.geometry.triangles.vertexStride = e.vertex + 1;
      CHECK_FALSE(SizeQueryIsValid(f.state, Signature(info, counts)));
    }
  }
  // A format the layer cannot describe as a vertex is never put to the driver, supported or not.
  BuildStateFixture f;
  SupportEveryFormat(f);
  VkAccelerationStructureGeometryKHR g = TriangleGeometry(0x1000);
  g.geometry.triangles.vertexFormat = VK_FORMAT_R32_SFLOAT;
  g.geometry.triangles.vertexStride = 4;
  const VkAccelerationStructureBuildGeometryInfoKHR info = OneGeometryInfo(kBottom, &g);
  const uint32_t counts[1] = {1};
  CHECK_FALSE(SizeQueryIsValid(f.state, Signature(info, counts)));
}

// One non-indexed triangle of R16G16B16_SFLOAT (6 bytes a vertex) at stride 6 reads 6 x 2 + 6 = 18 bytes.
std::vector<std::string> BuildThreeHalfVertices(VkDeviceSize input_bytes) {
  BuildStateFixture f;
  SupportEveryFormat(f);
  const VkDeviceMemory memory = f.Memory(1 << 20);
  const VkBuffer storage = f.Buffer(1 << 16, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR, memory);
  const VkBuffer scratch = f.Buffer(4096, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, memory, 1 << 16);
  const VkBuffer input = f.Buffer(input_bytes, kInput, memory, 2 << 16);
  VkAccelerationStructureGeometryKHR g = TriangleGeometry(f.AddressOf(input));
  g.geometry.triangles.vertexFormat = VK_FORMAT_R16G16B16_SFLOAT;
  g.geometry.triangles.vertexStride = 6;
  VkAccelerationStructureBuildGeometryInfoKHR info = OneGeometryInfo(kBottom, &g);
  info.dstAccelerationStructure = f.Structure(storage, 0, FakeSizes::Structure(1), kBottom);
  info.scratchData.deviceAddress = f.AddressOf(scratch);
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  const VkAccelerationStructureBuildRangeInfoKHR* ranges[1] = {&range};
  BuildCommand cmd{BuildCommandKind::kCmdBuild, "vkCmdBuildAccelerationStructuresKHR"};
  cmd.device = reinterpret_cast<VkDevice>(uintptr_t{0x1});
  cmd.command_buffer = reinterpret_cast<VkCommandBuffer>(uintptr_t{0x20});
  cmd.info_count = 1;
  cmd.infos = &info;
  cmd.ranges = ranges;
  f.Validate(cmd);
  return f.Take();
}

TEST_CASE("vertex formats: the vertex range of a 3-component 16-bit format counts all 6 bytes of the last vertex",
          "[unit][formats][addresses]") {
  CHECK(BuildThreeHalfVertices(17) ==
        std::vector<std::string>{"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03804"});
  CHECK(BuildThreeHalfVertices(18).empty());  // valid twin: the buffer holds exactly the 18 bytes read
}

}  // namespace
}  // namespace asval
