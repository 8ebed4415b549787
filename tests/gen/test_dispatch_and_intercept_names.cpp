// Intercept name list and dispatch-table loading, against a fake get-proc-addr that records what was asked.
#include <catch2/catch_test_macros.hpp>

#include <cstring>
#include <string>
#include <vector>

#include "vk_dispatch_table.h"
#include "vk_intercept_names.h"

namespace {

using asval::hooks::InterceptNameIndex;
using asval::hooks::kInterceptNameCount;
using asval::hooks::kInterceptNameIsDeviceLevel;
using asval::hooks::kInterceptNames;

bool IsIntercepted(const char* name) { return InterceptNameIndex(name) >= 0; }

TEST_CASE("intercept names are sorted and unique, so the binary search can find each one") {
  REQUIRE(kInterceptNameCount > 0);
  for (std::size_t i = 1; i < kInterceptNameCount; ++i) {
    INFO(kInterceptNames[i - 1] << " then " << kInterceptNames[i]);
    CHECK(std::strcmp(kInterceptNames[i - 1], kInterceptNames[i]) < 0);
  }
  for (std::size_t i = 0; i < kInterceptNameCount; ++i) {
    CHECK(InterceptNameIndex(kInterceptNames[i]) == static_cast<int>(i));
  }
}

TEST_CASE("intercepted commands are found under their canonical name and every alias") {
  CHECK(IsIntercepted("vkCmdBuildAccelerationStructuresKHR"));
  CHECK(IsIntercepted("vkCreateInstance"));
  CHECK(IsIntercepted("vkBindBufferMemory2"));
  CHECK(IsIntercepted("vkBindBufferMemory2KHR"));  // alias from VK_KHR_bind_memory2
}

TEST_CASE("names the layer does not intercept are not found") {
  CHECK_FALSE(IsIntercepted("vkGetBufferDeviceAddress"));  // dispatched, not intercepted
  CHECK_FALSE(IsIntercepted("vkGetBufferDeviceAddressKHR"));
  CHECK_FALSE(IsIntercepted("vkCmdDraw"));  // (vkQueueWaitIdle is intercepted since the capture, issue 12)
  CHECK_FALSE(IsIntercepted(""));
  CHECK_FALSE(IsIntercepted("vkCmdBuildAccelerationStructuresKHRX"));
  CHECK_FALSE(IsIntercepted("vkAAA"));  // before the first name
  CHECK_FALSE(IsIntercepted("vkZZZ"));  // after the last name
}

TEST_CASE("intercept names carry their level") {
  const auto level_of = [](const char* name) { return kInterceptNameIsDeviceLevel[InterceptNameIndex(name)]; };
  CHECK(level_of("vkCmdBuildAccelerationStructuresKHR"));
  CHECK(level_of("vkDestroyDevice"));
  CHECK_FALSE(level_of("vkCreateDevice"));  // first parameter is a VkPhysicalDevice
  CHECK_FALSE(level_of("vkCreateInstance"));
  CHECK_FALSE(level_of("vkDestroyDebugUtilsMessengerEXT"));
}

// A fake driver: answers only the names in `exposed` (with a distinct non-null pointer each) and records the
// order of every request.
struct FakeDriver {
  std::vector<std::string> exposed;
  std::vector<std::string> asked;
};
FakeDriver* g_driver = nullptr;

void FakeEntryPoint() {}

VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL FakeGetDeviceProcAddr(VkDevice, const char* name) {
  g_driver->asked.emplace_back(name);
  for (const std::string& exposed : g_driver->exposed) {
    if (exposed == name) return reinterpret_cast<PFN_vkVoidFunction>(&FakeEntryPoint);
  }
  return nullptr;
}

VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL FakeGetInstanceProcAddr(VkInstance, const char* name) {
  return FakeGetDeviceProcAddr(VK_NULL_HANDLE, name);
}

std::size_t CountAsked(const FakeDriver& driver, const std::string& name) {
  std::size_t count = 0;
  for (const std::string& asked : driver.asked) count += asked == name ? 1 : 0;
  return count;
}

TEST_CASE("device table falls back to aliases when the canonical name is missing") {
  FakeDriver driver;
  driver.exposed = {"vkGetBufferDeviceAddressKHR", "vkCreateBuffer"};  // a 1.1 driver with the KHR extension
  g_driver = &driver;
  asval::DeviceDispatchTable table;
  asval::InitDeviceDispatchTable(VK_NULL_HANDLE, &FakeGetDeviceProcAddr, &table);
  g_driver = nullptr;

  CHECK(table.GetBufferDeviceAddress != nullptr);
  CHECK(table.CreateBuffer != nullptr);
  CHECK(table.QueueSubmit2 == nullptr);  // neither vkQueueSubmit2 nor vkQueueSubmit2KHR exposed
  CHECK(table.CmdBuildAccelerationStructuresKHR == nullptr);
  // Canonical name first, then the aliases; a name without aliases is asked once.
  CHECK(CountAsked(driver, "vkGetBufferDeviceAddress") == 1);
  CHECK(CountAsked(driver, "vkGetBufferDeviceAddressKHR") == 1);
  CHECK(CountAsked(driver, "vkQueueSubmit2KHR") == 1);
  CHECK(CountAsked(driver, "vkCreateBuffer") == 1);
}

TEST_CASE("device table does not ask for aliases once the canonical name resolves") {
  FakeDriver driver;
  driver.exposed = {"vkGetBufferDeviceAddress"};
  g_driver = &driver;
  asval::DeviceDispatchTable table;
  asval::InitDeviceDispatchTable(VK_NULL_HANDLE, &FakeGetDeviceProcAddr, &table);
  g_driver = nullptr;

  CHECK(table.GetBufferDeviceAddress != nullptr);
  CHECK(CountAsked(driver, "vkGetBufferDeviceAddressKHR") == 0);
  CHECK(CountAsked(driver, "vkGetBufferDeviceAddressEXT") == 0);
}

TEST_CASE("instance table loads instance-level commands and their aliases") {
  FakeDriver driver;
  driver.exposed = {"vkGetPhysicalDeviceProperties2KHR", "vkDestroyInstance"};
  g_driver = &driver;
  asval::InstanceDispatchTable table;
  asval::InitInstanceDispatchTable(VK_NULL_HANDLE, &FakeGetInstanceProcAddr, &table);
  g_driver = nullptr;

  CHECK(table.GetPhysicalDeviceProperties2 != nullptr);
  CHECK(table.DestroyInstance != nullptr);
  CHECK(table.CreateDevice == nullptr);
  CHECK(CountAsked(driver, "vkCreateInstance") == 0);  // global: never in a table
  CHECK(CountAsked(driver, "vkCmdBuildAccelerationStructuresKHR") == 0);  // device level
}

}  // namespace
