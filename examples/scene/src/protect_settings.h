#pragma once
// The VkLayerSettingsCreateInfoEXT a fault run chains into VkInstanceCreateInfo: asval's `protect` setting on, so
// that a command or submission asval reports an error for never reaches the driver (and is announced by an
// ASVAL-Protect-Withheld notice). Layers other than asval ignore the entry; without asval nothing is protected,
// and the injector then keeps hang-prone faults to itself (inject.cpp).
#include <vulkan/vulkan.h>

#include "layer_settings_ext.h"  // VK_EXT_layer_settings, newer than the 1.3.239 headers

namespace scene {

class ProtectSettings {
 public:
  // `next`: the rest of the instance create info's pNext chain. Not copyable: the chain points into *this.
  explicit ProtectSettings(const void* next) {
    setting_ = VkLayerSettingEXT{"VK_LAYER_ASVAL_as_validation", "protect", VK_LAYER_SETTING_TYPE_BOOL32_EXT, 1, &on_};
    info_ = VkLayerSettingsCreateInfoEXT{VK_STRUCTURE_TYPE_LAYER_SETTINGS_CREATE_INFO_EXT, next, 1, &setting_};
  }
  ProtectSettings(const ProtectSettings&) = delete;
  ProtectSettings& operator=(const ProtectSettings&) = delete;

  const void* chain() const { return &info_; }

 private:
  const VkBool32 on_ = VK_TRUE;
  VkLayerSettingEXT setting_{};
  VkLayerSettingsCreateInfoEXT info_{};
};

}  // namespace scene
