#pragma once
// The instance and ray-tracing device every overhead program measures on, with whatever layers
// VK_INSTANCE_LAYERS names (the programs enable none themselves), and a debug messenger that counts what the
// layers report. The measured calls are valid: a layer that reported something would be measuring its
// reporting path, not its checks, so Finish() fails the run then.
#include <vulkan/vulkan.h>

#include <memory>

#include "vkkit.h"

namespace overhead {

class BenchDevice {
 public:
  // Throws std::runtime_error when no device has VK_KHR_acceleration_structure.
  BenchDevice();
  ~BenchDevice();
  BenchDevice(const BenchDevice&) = delete;
  BenchDevice& operator=(const BenchDevice&) = delete;

  vkkit::Device& device() { return *device_; }
  VkPhysicalDevice gpu() const { return gpu_; }

  // Destroys the device (messages of vkDestroyDevice are counted too), then prints
  //   ns_per_call: <wall ns per measured call> calls: <calls>
  //   validation messages: <errors> error(s), <warnings> warning(s)
  // and returns the exit status: 0, or 3 when a layer reported an error or a warning.
  int Finish(long calls, double seconds);

  // Messenger counts (the callback writes them).
  unsigned errors = 0;
  unsigned warnings = 0;

 private:
  std::unique_ptr<vkkit::Instance> instance_;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice gpu_ = VK_NULL_HANDLE;
  std::unique_ptr<vkkit::Device> device_;
};

// A pool on the queue family vkkit::Device takes its queue from (the first with compute), and a primary command
// buffer from it, begun for reuse (submitted many times).
VkCommandPool CreatePool(VkPhysicalDevice gpu, VkDevice device);
VkCommandBuffer BeginReusable(VkDevice device, VkCommandPool pool);
// Submits cb once, not measured (the driver compiles its pipelines at their first use), then `submissions` times,
// timing vkQueueSubmit alone (between the callgrind client requests: instrument.h) and waiting for the queue after
// each. Returns the seconds the measured submissions took.
double TimeSubmissions(VkQueue queue, VkCommandBuffer cb, int submissions);

// Runs body() and turns an exception into a message and exit status 1.
int Main(const char* program, int (*body)(int argc, char** argv), int argc, char** argv);

}  // namespace overhead
