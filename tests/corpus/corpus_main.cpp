// asval_corpus: `--list` prints every case's label as JSON; `CASE` runs that case and prints each validation
// message it receives as one JSON line, then {"done": true}. A line-per-message protocol survives a crash of
// the process half-way (an invalid call that no layer stopped may bring the driver down): what was reported
// before is kept.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <memory>
#include <string>

#include "corpus.h"

namespace corpus {

std::vector<Case>& Cases() {
  static std::vector<Case> cases;
  return cases;
}

namespace {

vkkit::Instance* current_instance = nullptr;

std::string Json(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\u%04x", c);
      out += escaped;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

void List() {
  std::printf("[\n");
  const std::vector<Case>& cases = Cases();
  for (size_t i = 0; i < cases.size(); ++i) {
    const Case& c = cases[i];
    std::string expected;
    for (const std::string& vuid : c.expected) expected += (expected.empty() ? "" : ", ") + Json(vuid);
    const std::string driver = c.test_driver ? ", \"test_driver\": " + Json(c.test_driver) : "";
    std::printf("  {\"name\": %s, \"family\": %s, \"pattern\": %s, \"expected\": [%s]%s}%s\n", Json(c.name).c_str(),
                Json(c.family).c_str(), Json(c.pattern).c_str(), expected.c_str(), driver.c_str(),
                i + 1 < cases.size() ? "," : "");
  }
  std::printf("]\n");
}

// Errors return VK_TRUE: whichever layer reports the fault keeps the call from the driver, as an app that stops
// on validation errors would (both layers honour it). ASVAL_CORPUS_MESSENGER=report-only makes it return VK_FALSE
// always, as a CI app's messenger (or none) does: only asval's protect mode then keeps a fault from the driver
// (scripts/device_protect.sh).
VKAPI_ATTR VkBool32 VKAPI_CALL Print(VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT,
                                     const VkDebugUtilsMessengerCallbackDataEXT* data, void*) {
  const bool error = severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  std::string text = data->pMessage ? data->pMessage : "";
  if (text.size() > 400) text.resize(400);
  std::printf("{\"severity\": \"%s\", \"id\": %s, \"text\": %s}\n", error ? "error" : "warning",
              Json(data->pMessageIdName ? data->pMessageIdName : "").c_str(), Json(text).c_str());
  std::fflush(stdout);
  static const bool report_only = [] {
    const char* mode = std::getenv("ASVAL_CORPUS_MESSENGER");
    return mode && std::strcmp(mode, "report-only") == 0;
  }();
  return error && !report_only ? VK_TRUE : VK_FALSE;
}

// ASVAL_CORPUS_DEVICE_FEATURES: the acceleration-structure features the case's device enables beyond the default,
// "host-commands", "indirect-build", "held-submissions" and / or the device extensions "nv-ray-tracing",
// "motion-blur" (VK_NV_ray_tracing_motion_blur) and "opacity-micromap" (VK_EXT_opacity_micromap); run_corpus.py asks
// for them where the case runs on asval's test driver, which has them all: tests/driver.
vkkit::DeviceOptions OptionsFromEnvironment() {
  vkkit::DeviceOptions options;
  const char* env = std::getenv("ASVAL_CORPUS_DEVICE_FEATURES");
  const std::string features = env ? env : "";
  options.host_commands = features.find("host-commands") != std::string::npos;
  options.indirect_build = features.find("indirect-build") != std::string::npos;
  // The test driver's held submissions (tests/driver/submission_hold.h) wait on a timeline semaphore.
  options.timeline_semaphore = features.find("held-submissions") != std::string::npos;
  if (features.find("nv-ray-tracing") != std::string::npos) {
    options.extensions.push_back(VK_NV_RAY_TRACING_EXTENSION_NAME);
  }
  // The features these extensions need, chained for the device's lifetime (one device per process).
  static VkPhysicalDeviceRayTracingMotionBlurFeaturesNV motion{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_MOTION_BLUR_FEATURES_NV};
  static VkPhysicalDeviceOpacityMicromapFeaturesEXT micromap{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_OPACITY_MICROMAP_FEATURES_EXT};
  if (features.find("motion-blur") != std::string::npos) {
    options.extensions.push_back(VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME);  // which the extension requires
    options.extensions.push_back(VK_NV_RAY_TRACING_MOTION_BLUR_EXTENSION_NAME);
    motion.rayTracingMotionBlur = VK_TRUE;
    motion.pNext = options.features;
    options.features = &motion;
  }
  if (features.find("opacity-micromap") != std::string::npos) {
    options.extensions.push_back(VK_EXT_OPACITY_MICROMAP_EXTENSION_NAME);
    micromap.micromap = VK_TRUE;
    micromap.pNext = options.features;
    options.features = &micromap;
  }
  return options;
}

int Run(const Case& c) {
  VkDebugUtilsMessengerCreateInfoEXT messenger_info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  messenger_info.messageSeverity =
      VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  messenger_info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
  messenger_info.pfnUserCallback = &Print;
  vkkit::InstanceOptions options;
  options.layers = vkkit::LayersFromEnvironment();
  options.pNext = &messenger_info;  // messages of instance creation and destruction
  vkkit::Instance instance(options);
  auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
      vkGetInstanceProcAddr(instance.handle(), "vkCreateDebugUtilsMessengerEXT"));
  auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
      vkGetInstanceProcAddr(instance.handle(), "vkDestroyDebugUtilsMessengerEXT"));
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  vkkit::Check(create(instance.handle(), &messenger_info, nullptr, &messenger), "vkCreateDebugUtilsMessengerEXT");
  VkPhysicalDevice gpu = instance.FindRayTracingGpu();
  if (!gpu) {
    std::fprintf(stderr, "asval_corpus: no device with VK_KHR_acceleration_structure\n");
    return 2;
  }
  current_instance = &instance;
  {
    vkkit::Device device(instance, gpu, OptionsFromEnvironment());
    c.body(device);
  }
  current_instance =
      nullptr;  // the device is destroyed before the messenger: reports made at vkDestroyDevice are printed too
  destroy(instance.handle(), messenger, nullptr);
  return 0;
}

}  // namespace

vkkit::Instance& CurrentInstance() { return *current_instance; }

}  // namespace corpus

int main(int argc, char** argv) {
  if (argc != 2 || std::strcmp(argv[1], "--help") == 0) {
    std::fprintf(stderr, "usage: asval_corpus --list | CASE\n");
    return argc == 2 ? 0 : 2;
  }
  if (std::strcmp(argv[1], "--list") == 0) {
    corpus::List();
    return 0;
  }
  for (const corpus::Case& c : corpus::Cases()) {
    if (c.name != std::string(argv[1])) continue;
    try {
      const int status = corpus::Run(c);
      if (status == 0) std::printf("{\"done\": true}\n");
      return status;
    } catch (const std::exception& e) {
      std::printf("{\"exception\": %s}\n", corpus::Json(e.what()).c_str());
      return 3;
    }
  }
  std::fprintf(stderr, "asval_corpus: no case '%s' (see --list)\n", argv[1]);
  return 2;
}
