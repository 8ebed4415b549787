// The bytes a host build reads, worked out by hand from the specification's addressing rules.
#include "host_inputs.h"

#include <catch2/catch_test_macros.hpp>

namespace asval_test_driver {
namespace {

VkAccelerationStructureGeometryTrianglesDataKHR Triangles(VkIndexType index_type, VkDeviceSize stride) {
  VkAccelerationStructureGeometryTrianglesDataKHR t{
      VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR};
  t.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
  t.vertexStride = stride;
  t.indexType = index_type;
  return t;
}

TEST_CASE("host inputs: indexed triangles read their indices at primitiveOffset and vertices up to the largest") {
  const auto t = Triangles(VK_INDEX_TYPE_UINT16, 16);
  const VkAccelerationStructureBuildRangeInfoKHR range{2, 8, 5, 0};  // 2 triangles, offset 8, firstVertex 5
  const HostSpan indices = IndexSpan(t, range);
  CHECK(indices.offset == 8);
  CHECK(indices.bytes == 12);  // 6 indices of 2 bytes
  const uint16_t values[6] = {0, 3, 1, 7, 2, 4};
  CHECK(LargestIndex(values, VK_INDEX_TYPE_UINT16, 6) == 7);
  const HostSpan vertices = VertexSpan(t, range, 7);
  CHECK(vertices.offset == 0);
  CHECK(vertices.bytes == 12 * 16 + 12);  // vertex 5 + 7 = 12 starts at 192, 12 bytes of R32G32B32
}

TEST_CASE("host inputs: non-indexed triangles read 3 vertices each from primitiveOffset") {
  const auto t = Triangles(VK_INDEX_TYPE_NONE_KHR, 12);
  const VkAccelerationStructureBuildRangeInfoKHR range{4, 24, 1, 0};
  CHECK(IndexSpan(t, range).bytes == 0);
  const HostSpan vertices = VertexSpan(t, range, 3 * 4 - 1);
  CHECK(vertices.offset == 24);
  CHECK(vertices.bytes == 12 * 12 + 12);  // vertices 1..12: the last at 12 * 12
}

TEST_CASE("host inputs: no triangle, no vertex; uint8 and uint32 indices") {
  const auto t = Triangles(VK_INDEX_TYPE_UINT32, 12);
  CHECK(VertexSpan(t, {0, 0, 0, 0}, 0).bytes == 0);
  const uint8_t small[3] = {9, 250, 3};
  CHECK(LargestIndex(small, VK_INDEX_TYPE_UINT8_EXT, 3) == 250);
  const uint32_t big[3] = {70000, 5, 4000000000u};
  CHECK(LargestIndex(big, VK_INDEX_TYPE_UINT32, 3) == 4000000000u);
  CHECK(LargestIndex(big, VK_INDEX_TYPE_UINT32, 0) == 0);
}

TEST_CASE("host inputs: the transform, boxes and instances") {
  auto t = Triangles(VK_INDEX_TYPE_NONE_KHR, 12);
  CHECK(TransformSpan(t, {1, 0, 0, 96}).bytes == 0);  // no transform
  static const float matrix[12] = {};
  t.transformData.hostAddress = matrix;
  const HostSpan transform = TransformSpan(t, {1, 0, 0, 96});
  CHECK(transform.offset == 96);
  CHECK(transform.bytes == 48);

  VkAccelerationStructureGeometryAabbsDataKHR aabbs{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_AABBS_DATA_KHR};
  aabbs.stride = 32;
  const HostSpan boxes = AabbSpan(aabbs, {3, 64, 0, 0});
  CHECK(boxes.offset == 64);
  CHECK(boxes.bytes == 2 * 32 + 24);
  CHECK(AabbSpan(aabbs, {0, 64, 0, 0}).bytes == 0);

  VkAccelerationStructureGeometryInstancesDataKHR instances{
      VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR};
  CHECK(InstanceSpan(instances, {3, 128, 0, 0}).bytes == 3 * 64);
  instances.arrayOfPointers = VK_TRUE;
  CHECK(InstanceSpan(instances, {3, 16, 0, 0}).bytes == 3 * 8);
  CHECK(InstanceSpan(instances, {3, 16, 0, 0}).offset == 16);
}

}  // namespace
}  // namespace asval_test_driver
