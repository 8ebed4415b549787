#pragma once
// The test driver's own entry points, for tests (reached through vkGetDeviceProcAddr: the layers above pass names they
// do not know down the chain).
#include <vulkan/vulkan.h>

// While `hold` is VK_TRUE, the device's submissions wait for the test driver to release them (VK_FALSE): work the
// layers above see submitted with no wait, and pending as long as the test needs (submission_hold.h).
extern "C" typedef VkResult(VKAPI_PTR* PFN_vkAsvalTestDriverHoldSubmissions)(VkDevice device, VkBool32 hold);
inline constexpr const char kAsvalTestDriverHoldSubmissions[] = "vkAsvalTestDriverHoldSubmissions";
