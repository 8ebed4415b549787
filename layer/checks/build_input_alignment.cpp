#include "build_input_alignment.h"

#include "build_report.h"
#include "rule_judge.h"
#include "vertex_format_alignment.h"
#include "vk_enum_string.h"

namespace asval {

bool ReportMisalignedInput(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j,
                           AlignedInput input, VkDeviceAddress address, uint32_t alignment) {
  const VkAccelerationStructureGeometryKHR& g = *GeometryAt(cmd.infos[i], j);
  const char* vuid = "pInfos-03711";
  const char* kind = "triangles";
  const char* field = "vertexData";
  std::string why;
  switch (input) {
    case AlignedInput::kVertexData:
      why = fmt::format(", the {} of vertexFormat {}", AlignmentOfVertexFormat(g.geometry.triangles.vertexFormat).What(),
                        string_VkFormat(g.geometry.triangles.vertexFormat));
      break;
    case AlignedInput::kIndexData:
      vuid = "pInfos-03712";
      field = "indexData";
      why = fmt::format(", the size of indexType {}", string_VkIndexType(g.geometry.triangles.indexType));
      break;
    case AlignedInput::kTransformData:
      vuid = "pInfos-03810";
      field = "transformData";
      break;
    case AlignedInput::kAabbData:
      vuid = "pInfos-03714";
      kind = "aabbs";
      field = "data";
      break;
    case AlignedInput::kInstances:
      vuid = "pInfos-03715";
      kind = "instances";
      field = "data";
      why = " (arrayOfPointers is VK_FALSE: an array of VkAccelerationStructureInstanceKHR)";
      break;
    case AlignedInput::kInstancePointers:
      vuid = "pInfos-03716";
      kind = "instances";
      field = "data";
      why = " (arrayOfPointers is VK_TRUE: an array of pointers)";
      break;
  }
  return ReportBuild(
      ctx, cmd, i, vuid,
      [&](std::string&) {
        return GeometryLocation(cmd, i, j).Field("geometry").Field(kind).Field(field).Field("deviceAddress");
      },
      "(0x{:x}) is not aligned to {} bytes{}.", address, alignment, why);
}

namespace {

[[gnu::cold, gnu::noinline]] bool ReportIndirectArray(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i,
                                                      bool stride) {
  if (stride) {
    return ReportBuild(ctx, cmd, i, "pIndirectStrides-03787",
                       [&](std::string&) { return cmd.Root().Field("pIndirectStrides", i); },
                       "({}) is not a multiple of 4.", cmd.indirect_strides[i]);
  }
  return ReportBuild(ctx, cmd, i, "pIndirectDeviceAddresses-03648",
                     [&](std::string&) { return cmd.Root().Field("pIndirectDeviceAddresses", i); },
                     "(0x{:x}) is not a multiple of 4.", cmd.indirect_addresses[i]);
}

bool ValidateIndirectArrays(const CheckContext& ctx, const BuildCommand& cmd) {
  bool skip = false;
  for (uint32_t i = 0; i < cmd.info_count; ++i) {
    if (cmd.indirect_addresses && (cmd.indirect_addresses[i] & 3) != 0) skip |= ReportIndirectArray(ctx, cmd, i, false);
    if (cmd.indirect_strides && (cmd.indirect_strides[i] & 3) != 0) skip |= ReportIndirectArray(ctx, cmd, i, true);
  }
  return skip;
}

}  // namespace

namespace {

// The infos the command's geometry pass flagged for these rules, walked with the reporting judge (out of line:
// the clean path only tests the flags).
[[gnu::noinline]] bool WalkInputAlignment(const CheckContext& ctx, const BuildCommand& cmd,
                                          const ResolvedBuild& resolved) {
  ReportingJudge judge{ctx};
  GeometryFactsReader facts(ctx.state);
  bool skip = false;
  for (uint32_t i = 0; i < cmd.info_count; ++i) {
    const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
    if (!(resolved.info(i).walks & kWalkInputAlignment) || !GeometriesWalkable(ctx, info)) continue;
    for (uint32_t j = 0; j < info.geometryCount; ++j) {
      const VkAccelerationStructureGeometryKHR* geometry = GeometryAt(info, j);
      if (geometry) skip |= InputAlignmentRules(ctx, cmd, i, j, facts.Read(*geometry), judge);
    }
  }
  return skip;
}

}  // namespace

bool ValidateInputAlignment(const CheckContext& ctx, const BuildCommand& cmd, const ResolvedBuild& resolved) {
  if (!cmd.infos || cmd.is_host()) return false;
  if (!(resolved.walks() & kWalkInputAlignment) && !cmd.is_indirect()) return false;  // before any call: no frame
  bool skip = false;
  // Infos in which the command's geometry pass found nothing for these rules are not walked again.
  if (resolved.walks() & kWalkInputAlignment) skip |= WalkInputAlignment(ctx, cmd, resolved);
  if (cmd.is_indirect()) skip |= ValidateIndirectArrays(ctx, cmd);
  return skip;
}

}  // namespace asval
