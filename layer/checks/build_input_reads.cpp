#include "build_input_reads.h"

#include "build_report.h"

namespace asval {

namespace {

// How a read is named in a message: its member of VkAccelerationStructureGeometryDataKHR, its field, the rule
// that makes its start a valid device address, and how its size was found.
struct ReadNames {
  const char* data_member;  // "triangles", "aabbs", "instances"
  const char* field;        // "vertexData", "indexData", "transformData", "data"
  const char* valid_vuid;   // "pInfos-03804", ...
  const char* how;          // ranged reads; unranged ones read "its first byte"
};

ReadNames NamesOf(InputKind kind) {
  switch (kind) {
    case InputKind::kVertices:
      return {"triangles", "vertexData", "pInfos-03804",
              "primitiveOffset + vertexStride x (firstVertex + 3 x primitiveCount - 1) + the vertex size"};
    case InputKind::kIndices:
      return {"triangles", "indexData", "pInfos-03806", "primitiveOffset + 3 x primitiveCount indices"};
    case InputKind::kTransform:
      return {"triangles", "transformData", "pInfos-03808", "transformOffset + one VkTransformMatrixKHR"};
    case InputKind::kAabbs:
      return {"aabbs", "data", "pInfos-03811", "primitiveOffset + stride x (primitiveCount - 1) + one VkAabbPositionsKHR"};
    case InputKind::kInstances:
      return {"instances", "data", "pInfos-03813", "primitiveOffset + primitiveCount VkAccelerationStructureInstanceKHR"};
    case InputKind::kInstancePointers:
      break;
  }
  return {"instances", "data", "pInfos-03813", "primitiveOffset + primitiveCount device addresses"};
}

}  // namespace

bool ReportInputRead(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j, const InputRead& read) {
  const DeviceState& state = ctx.state;
  if (SparseAddressBuffersExist(state)) {
    CountUnknownState(ctx);  // a sparse buffer the layer cannot see may hold these bytes
    return false;
  }
  const ReadNames names = NamesOf(read.kind);
  const char* how = read.ranged ? names.how : "its first byte";
  const auto location = [&](std::string&) {
    return GeometryLocation(cmd, i, j).Field("geometry").Field(names.data_member).Field(names.field).Field("deviceAddress");
  };
  bool skip = false;
  if (read.size == 1 && !FindBufferHolding(state, read.address, 1, 0)) {
    skip |= ReportBuild(ctx, cmd, i, names.valid_vuid, location, "(0x{:x}) is not a valid VkDeviceAddress: {}.",
                        read.address, DescribeBuffersAt(state, read.address));
  } else if (!FindBufferHolding(state, read.address, read.size, 0)) {
    skip |= ReportBuild(ctx, cmd, i, names.valid_vuid, location,
                        "(0x{:x}) is not a valid VkDeviceAddress for the {} bytes this build reads from it "
                        "[0x{:x}, 0x{:x}) ({}): no single buffer holds them; {}.",
                        read.address, read.size, read.address, SaturatingAdd(read.address, read.size), how,
                        DescribeBuffersAt(state, read.address));
  }
  if (FindBufferHolding(state, read.address, 1, 0) && !FindBufferHolding(state, read.address, 1, kInputUsage)) {
    skip |= ReportBuild(ctx, cmd, i, "geometry-03673", location,
                        "(0x{:x}) comes from a buffer created without "
                        "VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR: {}.",
                        read.address, DescribeBuffersAt(state, read.address));
  }
  return skip;
}

}  // namespace asval
