#include "bench_device.h"

#include <chrono>
#include <cstdio>
#include <exception>
#include <stdexcept>
#include <vector>

#include "instrument.h"

namespace overhead {

namespace {

VKAPI_ATTR VkBool32 VKAPI_CALL Count(VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT,
                                     const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  BenchDevice& bench = *static_cast<BenchDevice*>(user);
  const bool error = severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  error ? ++bench.errors : ++bench.warnings;
  // The first few are shown: they say why a run was refused.
  if (bench.errors + bench.warnings <= 3) {
    std::fprintf(stderr, "%s: %s\n", error ? "error" : "warning", data->pMessage ? data->pMessage : "");
  }
  return VK_FALSE;
}

VkDebugUtilsMessengerCreateInfoEXT MessengerInfo(BenchDevice* bench) {
  VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  info.messageSeverity =
      VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT;
  // Validation messages only: the loader's general ones (e.g. that VK_LOADER_LAYERS_DISABLE switched a layer
  // off) say nothing about the calls measured.
  info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
  info.pfnUserCallback = Count;
  info.pUserData = bench;
  return info;
}

void PrintDevice(VkPhysicalDevice gpu) {
  VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &driver};
  vkGetPhysicalDeviceProperties2(gpu, &props);
  std::printf("device: %s; driver: %s %s\n", props.properties.deviceName, driver.driverName, driver.driverInfo);
  // The layers the loader activated (it answers this deprecated query with the instance's layers): the runner
  // checks that each configuration ran with the layers it names, and with no other.
  uint32_t count = 0;
  vkEnumerateDeviceLayerProperties(gpu, &count, nullptr);
  std::vector<VkLayerProperties> layers(count);
  vkEnumerateDeviceLayerProperties(gpu, &count, layers.data());
  std::printf("layers:");
  for (uint32_t i = 0; i < count; ++i) std::printf("%s%s", i ? "," : " ", layers[i].layerName);
  std::printf("\n");
}

}  // namespace

BenchDevice::BenchDevice() {
  // Chained into the create info as well, so that vkCreateInstance's and vkDestroyInstance's messages count.
  const VkDebugUtilsMessengerCreateInfoEXT messenger = MessengerInfo(this);
  vkkit::InstanceOptions options;  // no layers named: VK_INSTANCE_LAYERS decides
  options.pNext = &messenger;
  instance_ = std::make_unique<vkkit::Instance>(options);
  auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
      vkGetInstanceProcAddr(instance_->handle(), "vkCreateDebugUtilsMessengerEXT"));
  vkkit::Check(create(instance_->handle(), &messenger, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
  gpu_ = instance_->FindRayTracingGpu();
  if (!gpu_) throw std::runtime_error("no device with VK_KHR_acceleration_structure");
  PrintDevice(gpu_);
  device_ = std::make_unique<vkkit::Device>(*instance_, gpu_);
}

BenchDevice::~BenchDevice() {
  device_.reset();
  if (messenger_) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_->handle(), "vkDestroyDebugUtilsMessengerEXT"));
    destroy(instance_->handle(), messenger_, nullptr);
  }
}

int BenchDevice::Finish(long calls, double seconds) {
  device_.reset();
  std::printf("ns_per_call: %.1f calls: %ld\n", seconds * 1e9 / static_cast<double>(calls), calls);
  std::printf("validation messages: %u error(s), %u warning(s)\n", errors, warnings);
  return errors + warnings ? 3 : 0;
}

VkCommandPool CreatePool(VkPhysicalDevice gpu, VkDevice device) {
  uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(gpu, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(gpu, &count, families.data());
  uint32_t family = 0;
  while (family < count && !(families[family].queueFlags & VK_QUEUE_COMPUTE_BIT)) ++family;
  VkCommandPoolCreateInfo info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  info.queueFamilyIndex = family;
  VkCommandPool pool = VK_NULL_HANDLE;
  vkkit::Check(vkCreateCommandPool(device, &info, nullptr, &pool), "vkCreateCommandPool");
  return pool;
}

VkCommandBuffer BeginReusable(VkDevice device, VkCommandPool pool) {
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = pool;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  VkCommandBuffer cb = VK_NULL_HANDLE;
  vkkit::Check(vkAllocateCommandBuffers(device, &alloc, &cb), "vkAllocateCommandBuffers");
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};  // no ONE_TIME_SUBMIT
  vkkit::Check(vkBeginCommandBuffer(cb, &begin), "vkBeginCommandBuffer");
  return cb;
}

namespace {

void Submit(VkQueue queue, VkCommandBuffer cb) {
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cb;
  vkkit::Check(vkQueueSubmit(queue, 1, &submit, VK_NULL_HANDLE), "vkQueueSubmit");
}

}  // namespace

double TimeSubmissions(VkQueue queue, VkCommandBuffer cb, int submissions) {
  Submit(queue, cb);
  vkkit::Check(vkQueueWaitIdle(queue), "vkQueueWaitIdle");
  double seconds = 0;
  for (int s = 0; s < submissions; ++s) {
    const auto start = std::chrono::steady_clock::now();
    OVERHEAD_START_INSTRUMENTATION;
    Submit(queue, cb);
    OVERHEAD_STOP_INSTRUMENTATION;
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    vkkit::Check(vkQueueWaitIdle(queue), "vkQueueWaitIdle");
  }
  return seconds;
}

int Main(const char* program, int (*body)(int argc, char** argv), int argc, char** argv) {
  try {
    return body(argc, argv);
  } catch (const std::exception& e) {
    std::fflush(stdout);
    std::fprintf(stderr, "%s: %s\n", program, e.what());
    return 1;
  }
}

}  // namespace overhead
