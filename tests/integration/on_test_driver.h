#pragma once
// Tests that need what no local driver has (host commands) run on asval's test driver (docs/testing.md): the
// layers the run names (ASVAL_TEST_LAYERS: asval alone, or asval over the Khronos layer), then the test driver,
// directly over lavapipe. Declare an OnTestDriver before the fixture.
#include <string>

#include "scoped_env.h"
#include "vkkit.h"

namespace asval_test {

std::string LayersWithTestDriver();

class OnTestDriver {
 public:
  OnTestDriver() : layers_("ASVAL_TEST_LAYERS", LayersWithTestDriver()) {}

  // The device options of a program that enables accelerationStructureHostCommands.
  static vkkit::DeviceOptions HostCommands() {
    vkkit::DeviceOptions options;
    options.host_commands = true;
    return options;
  }

 private:
  ScopedEnvironment layers_;
};

}  // namespace asval_test
