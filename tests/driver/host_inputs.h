#pragma once
// What a host build reads from each host address of a geometry (the test driver copies exactly these bytes into
// device memory before it builds on the device): pure logic, tested on its own (host_inputs_test.cpp).
#include <vulkan/vulkan.h>

#include <cstdint>

namespace asval_test_driver {

// A span of bytes read at a host address: [offset, offset + bytes) from the address the geometry names.
struct HostSpan {
  uint64_t offset = 0;
  uint64_t bytes = 0;
};

// The bytes of one vertex of `format` (0 for a format the driver does not know).
uint32_t VertexFormatBytes(VkFormat format);

// The bytes one index of `type` takes (0 for VK_INDEX_TYPE_NONE_KHR and unknown types).
uint32_t IndexBytes(VkIndexType type);

// The triangles' index bytes read: primitiveOffset, 3 indices per triangle. Empty when not indexed.
HostSpan IndexSpan(const VkAccelerationStructureGeometryTrianglesDataKHR& triangles,
                   const VkAccelerationStructureBuildRangeInfoKHR& range);

// The vertex bytes read, given the largest vertex index the triangles use (`largest_index`, before firstVertex is
// added: for indexed triangles the largest index read, for non-indexed 3 * primitiveCount - 1). Non-indexed
// triangles start at primitiveOffset. Empty when primitiveCount is 0.
HostSpan VertexSpan(const VkAccelerationStructureGeometryTrianglesDataKHR& triangles,
                    const VkAccelerationStructureBuildRangeInfoKHR& range, uint64_t largest_index);

// The largest of `count` indices of `type` at `indices` (0 when count is 0).
uint64_t LargestIndex(const void* indices, VkIndexType type, uint64_t count);

// The transform's 48 bytes at transformOffset, when the triangles have one.
HostSpan TransformSpan(const VkAccelerationStructureGeometryTrianglesDataKHR& triangles,
                       const VkAccelerationStructureBuildRangeInfoKHR& range);

// The boxes read: primitiveOffset, then one VkAabbPositionsKHR per stride.
HostSpan AabbSpan(const VkAccelerationStructureGeometryAabbsDataKHR& aabbs,
                  const VkAccelerationStructureBuildRangeInfoKHR& range);

// The instances (or, with arrayOfPointers, the pointers) read: primitiveOffset, then 64 (or 8) bytes each.
HostSpan InstanceSpan(const VkAccelerationStructureGeometryInstancesDataKHR& instances,
                      const VkAccelerationStructureBuildRangeInfoKHR& range);

// Moves a triangle geometry's firstVertex into its vertex address (range.firstVertex becomes 0), which reads the
// same vertices by the specification's addressing. The driver below is always given 0: the specification adds
// firstVertex once (to each index, or to the non-indexed vertex number), lavapipe 25 adds it twice (to the base
// address as well). Other geometries are left as they are.
void FoldFirstVertex(VkAccelerationStructureGeometryKHR& geometry, VkAccelerationStructureBuildRangeInfoKHR& range);

}  // namespace asval_test_driver
