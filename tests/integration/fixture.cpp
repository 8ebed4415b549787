#include "fixture.h"

#include <stdexcept>

namespace asval_test {

Fixture::Fixture(const void* extra_pnext, const vkkit::DeviceOptions& device) : monitor_(std::make_unique<Monitor>()) {
  pnext_info_ = monitor_->create_info();
  pnext_info_.pNext = extra_pnext;
  vkkit::InstanceOptions options;
  options.layers = vkkit::LayersFromEnvironment();
  options.pNext = &pnext_info_;
  instance_ = std::make_unique<vkkit::Instance>(options);
  auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
      vkGetInstanceProcAddr(instance_->handle(), "vkCreateDebugUtilsMessengerEXT"));
  vkkit::Check(create(instance_->handle(), &monitor_->create_info(), nullptr, &messenger_),
               "vkCreateDebugUtilsMessengerEXT");
  VkPhysicalDevice gpu = instance_->FindRayTracingGpu();
  if (!gpu) throw std::runtime_error("no device with VK_KHR_acceleration_structure (is lavapipe installed?)");
  device_ = std::make_unique<vkkit::Device>(*instance_, gpu, device);
}

Fixture::~Fixture() {
  device_.reset();
  auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
      vkGetInstanceProcAddr(instance_->handle(), "vkDestroyDebugUtilsMessengerEXT"));
  destroy(instance_->handle(), messenger_, nullptr);
  instance_.reset();
}

}  // namespace asval_test
