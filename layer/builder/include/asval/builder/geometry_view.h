// Host-memory views of acceleration-structure build inputs, as the layer hands them to the builder.
// Each view mirrors the Vulkan structures (geometry data + VkAccelerationStructureBuildRangeInfoKHR) so the
// builder applies primitiveOffset / firstVertex / transformOffset itself, exactly as the spec says, and
// checks every read against the byte sizes the layer copied (no out-of-bounds read on hostile input).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vulkan/vulkan_core.h>

namespace asval::builder {

// VkAccelerationStructureBuildRangeInfoKHR, repeated so this header needs no loader types.
struct BuildRange {
    uint32_t primitiveCount = 0;
    uint32_t primitiveOffset = 0;  // bytes
    uint32_t firstVertex = 0;      // triangles only
    uint32_t transformOffset = 0;  // bytes, triangles only
};

// VK_GEOMETRY_TYPE_TRIANGLES_KHR. Pointers are host copies of vertexData / indexData / transformData;
// each *Bytes says how many bytes starting at that pointer may be read.
struct TriangleGeometryView {
    const void* vertexData = nullptr;
    size_t vertexDataBytes = 0;
    VkFormat vertexFormat = VK_FORMAT_UNDEFINED;
    uint64_t vertexStride = 0;
    uint32_t maxVertex = 0;
    VkIndexType indexType = VK_INDEX_TYPE_NONE_KHR;
    const void* indexData = nullptr;
    size_t indexDataBytes = 0;
    const void* transformData = nullptr;  // null: no transform (VkTransformMatrixKHR otherwise)
    size_t transformDataBytes = 0;
    BuildRange range;
    // VK_NV_ray_tracing_motion_blur: VkAccelerationStructureGeometryMotionTrianglesDataNV::vertexData, the
    // vertex positions at time 1.0 (vertexData holds time 0.0). Same format, stride, indices, firstVertex,
    // primitiveOffset and transform ("indexing ... is equivalent to the basic vertex position data").
    // Null: not a motion geometry.
    const void* motionVertexData = nullptr;
    size_t motionVertexDataBytes = 0;
};

// VK_GEOMETRY_TYPE_AABBS_KHR (VkAabbPositionsKHR records, `stride` apart).
struct AabbGeometryView {
    const void* data = nullptr;
    size_t dataBytes = 0;
    uint64_t stride = 0;
    BuildRange range;
};

// VK_GEOMETRY_TYPE_INSTANCES_KHR. Plain: `data` holds VkAccelerationStructureInstanceKHR records.
// arrayOfPointers: `data` holds `const void*` host pointers (one per instance, after primitiveOffset),
// each to one VkAccelerationStructureInstanceKHR of 64 readable bytes; a null pointer is an input error.
//
// motionInstances (the build sets VK_BUILD_ACCELERATION_STRUCTURE_MOTION_BIT_NV):
//  * plain: `data` holds VkAccelerationStructureMotionInstanceNV records (152 bytes each) at the spec's
//    stride of kMotionInstanceStride = 160 bytes, starting at primitiveOffset; each needs 152 readable bytes;
//  * arrayOfPointers: each pointer's low 4 bits hold a VkAccelerationStructureMotionInstanceTypeNV and the
//    pointer with those bits cleared addresses the record itself: VkAccelerationStructureInstanceKHR (64
//    readable bytes), VkAccelerationStructureMatrixMotionInstanceNV (112) or ...SRTMotionInstanceNV (144).
struct InstanceGeometryView {
    const void* data = nullptr;
    size_t dataBytes = 0;
    bool arrayOfPointers = false;
    BuildRange range;
    bool motionInstances = false;
};

// "VkAccelerationStructureMotionInstanceNV structures have a stride of 160 bytes" (the struct is 152).
constexpr uint64_t kMotionInstanceStride = 160;
constexpr uint64_t kMotionInstanceBytes = 152;

}  // namespace asval::builder
