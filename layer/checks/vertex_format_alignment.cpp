#include "vertex_format_alignment.h"

namespace asval::vertex_format_detail {

VertexFormatAlignment ExtensionFormatAlignment(VkFormat format) {
  switch (format) {
    case VK_FORMAT_A4R4G4B4_UNORM_PACK16:
    case VK_FORMAT_A4B4G4R4_UNORM_PACK16:
      return {2, true};
    case VK_FORMAT_R16G16_S10_5_NV:
      return {2, false};
    default:
      return {};
  }
}

}  // namespace asval::vertex_format_detail
