#pragma once
// What every check sees: the device's shadow state (read-only) and the reporter. Checks return true when
// the app asked (through a callback returning VK_TRUE) that the call not be passed down.
#include "device_state.h"
#include "layer_settings.h"
#include "location.h"
#include "reporter.h"

namespace asval {

struct CheckContext {
  const DeviceState& state;
  Reporter& reporter;
  uint32_t enabled_checks;  // LayerSettingFlagBits kCheck*: the families the settings enable

  bool Enabled(LayerSettingFlagBits family) const { return (enabled_checks & family) != 0; }
};

}  // namespace asval
