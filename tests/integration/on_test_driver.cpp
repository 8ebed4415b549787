#include "on_test_driver.h"

namespace asval_test {

std::string LayersWithTestDriver() {
  std::string list;
  for (const std::string& layer : vkkit::LayersFromEnvironment()) list += layer + ":";
  return list + "VK_LAYER_ASVAL_test_driver";
}

}  // namespace asval_test
