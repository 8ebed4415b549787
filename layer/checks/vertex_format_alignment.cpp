#include "vertex_format_alignment.h"

namespace asval {

VertexFormatAlignment AlignmentOfVertexFormat(VkFormat format) {
  // The core 1.0 colour formats are laid out in runs of the same component size (vulkan_core.h), so ranges
  // describe them exactly; tests/unit cross-checks every vertex format of the reference builder.
  const int value = static_cast<int>(format);
  if (value == VK_FORMAT_R4G4_UNORM_PACK8) return {1, true};
  if (value >= VK_FORMAT_R4G4B4A4_UNORM_PACK16 && value <= VK_FORMAT_A1R5G5B5_UNORM_PACK16) return {2, true};
  if (value >= VK_FORMAT_R8_UNORM && value <= VK_FORMAT_B8G8R8A8_SRGB) return {1, false};
  if (value >= VK_FORMAT_A8B8G8R8_UNORM_PACK32 && value <= VK_FORMAT_A2B10G10R10_SINT_PACK32) return {4, true};
  if (value >= VK_FORMAT_R16_UNORM && value <= VK_FORMAT_R16G16B16A16_SFLOAT) return {2, false};
  if (value >= VK_FORMAT_R32_UINT && value <= VK_FORMAT_R32G32B32A32_SFLOAT) return {4, false};
  if (value >= VK_FORMAT_R64_UINT && value <= VK_FORMAT_R64G64B64A64_SFLOAT) return {8, false};
  if (value == VK_FORMAT_B10G11R11_UFLOAT_PACK32 || value == VK_FORMAT_E5B9G9R9_UFLOAT_PACK32) return {4, true};
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

int IndexTypeSize(VkIndexType type) {
  switch (type) {
    case VK_INDEX_TYPE_NONE_KHR:
      return 0;
    case VK_INDEX_TYPE_UINT16:
      return 2;
    case VK_INDEX_TYPE_UINT32:
      return 4;
    case VK_INDEX_TYPE_UINT8_EXT:
      return 1;
    default:
      return -1;
  }
}

}  // namespace asval
