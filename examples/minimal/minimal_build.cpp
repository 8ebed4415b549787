// minimal_build: the smallest program that shows asval at work. It builds one valid bottom-level
// acceleration structure (asval stays silent), then records the same build with a scratch address that
// breaks the device's alignment rule (asval reports VUID-...-pInfos-03710).
//
// With a debug messenger (default) the messenger prints each finding and returns VK_TRUE for errors, which
// tells the layer not to pass the invalid call to the driver. With --no-messenger the findings go to stderr
// and the invalid command buffer is recorded but never submitted. Under asval's protect mode (scripts/asval-run)
// the submission of the invalid command buffer fails (VK_ERROR_VALIDATION_FAILED_EXT) and the program exits 1.
#include <cstdio>
#include <cstring>
#include <exception>
#include <vector>

#include "vkkit.h"

namespace {

int g_findings = 0;

VKAPI_ATTR VkBool32 VKAPI_CALL PrintFinding(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                            VkDebugUtilsMessageTypeFlagsEXT,
                                            const VkDebugUtilsMessengerCallbackDataEXT* data, void*) {
  ++g_findings;
  std::printf("--- finding %d (%s) ---\n%s\n", g_findings, data->pMessageIdName ? data->pMessageIdName : "?",
              data->pMessage);
  return severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? VK_TRUE : VK_FALSE;
}

}  // namespace

int main(int argc, char** argv) {
  bool use_messenger = true;
  bool failed = false;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--no-messenger") == 0) {
      use_messenger = false;
    } else {
      std::fprintf(stderr, "usage: %s [--no-messenger]\n", argv[0]);
      return 2;
    }
  }
  try {
    VkDebugUtilsMessengerCreateInfoEXT messenger{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    messenger.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                                VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    messenger.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
    messenger.pfnUserCallback = PrintFinding;

    // Layers come from the environment (VK_INSTANCE_LAYERS), as in any app.
    vkkit::InstanceOptions options;
    vkkit::Instance instance(options);
    VkDebugUtilsMessengerEXT handle = VK_NULL_HANDLE;
    auto create_messenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance.handle(), "vkCreateDebugUtilsMessengerEXT"));
    auto destroy_messenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance.handle(), "vkDestroyDebugUtilsMessengerEXT"));
    if (use_messenger) vkkit::Check(create_messenger(instance.handle(), &messenger, nullptr, &handle), "messenger");

    VkPhysicalDevice gpu = instance.FindRayTracingGpu();
    if (!gpu) {
      std::fprintf(stderr, "minimal_build: no device with VK_KHR_acceleration_structure\n");
      return 1;
    }
    {
      vkkit::Device device(instance, gpu);
      std::printf("scratch alignment required by the device: %u bytes\n",
                  device.as_properties().minAccelerationStructureScratchOffsetAlignment);

      vkkit::TriangleBuild build(device);
      device.SetName(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, reinterpret_cast<uint64_t>(build.blas.handle),
                     "triangle BLAS");
      std::printf("1. valid build (scratch at its buffer's start)\n");
      device.OneShot([&](VkCommandBuffer cb) { build.Record(device, cb); });

      const VkDeviceSize misalignment = device.as_properties().minAccelerationStructureScratchOffsetAlignment / 2;
      std::printf("2. build with the scratch address moved by %llu bytes (breaks the alignment rule)\n",
                  static_cast<unsigned long long>(misalignment));
      std::fflush(stdout);  // keep the order of our lines and the layer's stderr lines
      build.UseScratchOffset(misalignment ? misalignment : 1);
      try {
        device.OneShot([&](VkCommandBuffer cb) { build.Record(device, cb); }, /*submit=*/use_messenger);
      } catch (const std::exception& e) {
        // Under asval's protect mode (on in scripts/asval-run) the submission of a command buffer whose build asval
        // kept from the driver is withheld too: vkQueueSubmit returns VK_ERROR_VALIDATION_FAILED_EXT. Say so, clean
        // up (a leak checker must not blame this program), and fail.
        std::fprintf(stderr, "minimal_build: %s\n", e.what());
        failed = true;
      }
      build.Release(device);
    }
    if (handle) destroy_messenger(instance.handle(), handle, nullptr);
    if (use_messenger) std::printf("asval reported %d finding(s)\n", g_findings);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "minimal_build: %s\n", e.what());
    return 1;
  }
  return failed ? 1 : 0;
}
