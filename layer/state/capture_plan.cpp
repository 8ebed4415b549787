#include "capture_plan.h"

#include "asval/builder/vertex_format.h"
#include "asval/vertex_formats.h"
#include "vk_struct_chain.h"

namespace asval {

namespace {

constexpr VkDeviceSize kAabbBytes = sizeof(VkAabbPositionsKHR);                      // 24
constexpr VkDeviceSize kInstanceBytes = sizeof(VkAccelerationStructureInstanceKHR);  // 64
constexpr VkDeviceSize kTransformBytes = sizeof(VkTransformMatrixKHR);               // 48

}  // namespace

bool PlanCapturedGeometry(const VkAccelerationStructureGeometryKHR& g,
                          const VkAccelerationStructureBuildRangeInfoKHR& r, bool host, CapturedGeometry* out,
                          std::vector<CaptureSource>& sources, CaptureSkip* why, bool motion) {
  const auto not_captured = [why](CaptureSkip reason) {
    *why = reason;
    return false;
  };
  // Host builds give host pointers in the same unions: read the member the command uses.
  const auto address = [host](const VkDeviceOrHostAddressConstKHR& a) -> uint64_t {
    return host ? reinterpret_cast<uint64_t>(a.hostAddress) : a.deviceAddress;
  };
  out->type = g.geometryType;
  out->range.primitiveCount = r.primitiveCount;
  const VkDeviceSize n = r.primitiveCount;
  if (g.geometryType == VK_GEOMETRY_TYPE_TRIANGLES_KHR) {
    const VkAccelerationStructureGeometryTrianglesDataKHR& t = g.geometry.triangles;
    const VertexFormatInfo& format = VertexFormatFacts(t.vertexFormat);
    const int index_bytes = builder::IndexTypeBytes(t.indexType);  // the builder's: it reads them
    if (!format.decodable || index_bytes < 0) return not_captured(CaptureSkip::kGeometryNotCaptured);
    out->vertex_format = t.vertexFormat;
    out->vertex_stride = t.vertexStride;
    out->index_type = t.indexType;
    // Motion: the vertices at time 1 come from the same range of another address, in the same format and stride.
    const VkAccelerationStructureGeometryMotionTrianglesDataNV* at_1 =
        motion ? FindInChain<VkAccelerationStructureGeometryMotionTrianglesDataNV>(
                     t.pNext, VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_MOTION_TRIANGLES_DATA_NV)
               : nullptr;
    if (motion && !at_1) return not_captured(CaptureSkip::kGeometryNotCaptured);
    out->motion = at_1 != nullptr;
    if (n == 0) return true;
    if (address(t.vertexData) == 0) return not_captured(CaptureSkip::kNullInput);
    if (at_1 && address(at_1->vertexData) == 0) return not_captured(CaptureSkip::kNullInput);
    if (address(t.transformData) != 0) {
      sources.push_back(CaptureSource{SaturatingAddBytes(address(t.transformData), r.transformOffset), kTransformBytes,
                                      &out->transform, true});
    }
    if (index_bytes == 0) {
      // Vertex k of the range is read at primitiveOffset + stride * (firstVertex + k); the last one for its size.
      const VkDeviceSize first =
          SaturatingAddBytes(r.primitiveOffset, SaturatingMulBytes(t.vertexStride, r.firstVertex));
      const VkDeviceSize bytes =
          SaturatingAddBytes(SaturatingMulBytes(t.vertexStride, SaturatingMulBytes(3, n) - 1), format.vertexBytes);
      out->max_vertex = t.maxVertex >= r.firstVertex ? t.maxVertex - r.firstVertex : 0;
      sources.push_back(CaptureSource{SaturatingAddBytes(address(t.vertexData), first), bytes, &out->data});
      if (at_1) {
        sources.push_back(CaptureSource{SaturatingAddBytes(address(at_1->vertexData), first), bytes, &out->motion_data});
      }
    } else {
      if (address(t.indexData) == 0) return not_captured(CaptureSkip::kNullInput);
      // Indices from primitiveOffset; vertices index + firstVertex up to maxVertex, from vertexData.
      out->max_vertex = t.maxVertex;
      out->range.firstVertex = r.firstVertex;
      sources.push_back(CaptureSource{SaturatingAddBytes(address(t.indexData), r.primitiveOffset),
                                      SaturatingMulBytes(SaturatingMulBytes(3, n), index_bytes), &out->indices});
      const VkDeviceSize vertex_bytes =
          SaturatingAddBytes(SaturatingMulBytes(t.vertexStride, t.maxVertex), format.vertexBytes);
      sources.push_back(CaptureSource{address(t.vertexData), vertex_bytes, &out->data});
      if (at_1) sources.push_back(CaptureSource{address(at_1->vertexData), vertex_bytes, &out->motion_data});
    }
    return true;
  }
  if (g.geometryType == VK_GEOMETRY_TYPE_AABBS_KHR) {
    const VkAccelerationStructureGeometryAabbsDataKHR& a = g.geometry.aabbs;
    out->aabb_stride = a.stride;
    if (n == 0) return true;
    if (address(a.data) == 0) return not_captured(CaptureSkip::kNullInput);
    sources.push_back(CaptureSource{SaturatingAddBytes(address(a.data), r.primitiveOffset),
                                    SaturatingAddBytes(SaturatingMulBytes(a.stride, n - 1), kAabbBytes), &out->data});
    return true;
  }
  if (g.geometryType == VK_GEOMETRY_TYPE_INSTANCES_KHR) {
    const VkAccelerationStructureGeometryInstancesDataKHR& in = g.geometry.instances;
    // Arrays of pointers: the pointers (their alignment is a rule); where they point is known on the device alone,
    // when the build executes, so the records are a second stage, gathered on the device by the layer's dispatch
    // where it has one (layer/capture), else unknown.
    out->array_of_pointers = in.arrayOfPointers == VK_TRUE;
    if (n == 0) return true;
    if (address(in.data) == 0) return not_captured(CaptureSkip::kNullInput);
    const VkDeviceSize record_bytes = out->array_of_pointers ? sizeof(VkDeviceAddress) : kInstanceBytes;
    sources.push_back(CaptureSource{SaturatingAddBytes(address(in.data), r.primitiveOffset),
                                    SaturatingMulBytes(record_bytes, n),
                                    out->array_of_pointers ? &out->pointers : &out->data});
    return true;
  }
  return not_captured(CaptureSkip::kGeometryNotCaptured);  // a geometry type the builder does not know
}

}  // namespace asval
