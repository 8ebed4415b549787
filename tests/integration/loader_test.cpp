// The loader interface: the layer is found, lists its extensions, and hands out its own functions for
// the commands it intercepts (every alias included) and the next element's for everything else.
#include <dlfcn.h>

#include <catch2/catch_test_macros.hpp>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fixture.h"

namespace asval_test {
namespace {

bool InsideLayer(PFN_vkVoidFunction fn) {
  Dl_info info{};
  if (!fn || !dladdr(reinterpret_cast<void*>(fn), &info) || !info.dli_fname) return false;
  return std::strstr(info.dli_fname, "libVkLayer_asval_as_validation.so") != nullptr;
}

TEST_CASE("the layer is listed with its instance extensions", "[integration][loader]") {
  uint32_t count = 0;
  REQUIRE(vkEnumerateInstanceLayerProperties(&count, nullptr) == VK_SUCCESS);
  std::vector<VkLayerProperties> layers(count);
  REQUIRE(vkEnumerateInstanceLayerProperties(&count, layers.data()) == VK_SUCCESS);
  bool found = false;
  for (const VkLayerProperties& l : layers) found |= std::strcmp(l.layerName, "VK_LAYER_ASVAL_as_validation") == 0;
  REQUIRE(found);

  REQUIRE(vkEnumerateInstanceExtensionProperties("VK_LAYER_ASVAL_as_validation", &count, nullptr) == VK_SUCCESS);
  std::vector<VkExtensionProperties> exts(count);
  REQUIRE(vkEnumerateInstanceExtensionProperties("VK_LAYER_ASVAL_as_validation", &count, exts.data()) == VK_SUCCESS);
  std::vector<std::string> names;
  for (const VkExtensionProperties& e : exts) names.push_back(e.extensionName);
  CHECK(std::find(names.begin(), names.end(), "VK_EXT_debug_utils") != names.end());
  CHECK(std::find(names.begin(), names.end(), "VK_EXT_layer_settings") != names.end());
}

VkLayerProperties FindAsval(const std::vector<VkLayerProperties>& layers) {
  for (const VkLayerProperties& l : layers) {
    if (std::strcmp(l.layerName, "VK_LAYER_ASVAL_as_validation") == 0) return l;
  }
  FAIL("VK_LAYER_ASVAL_as_validation is not listed");
  return {};
}

TEST_CASE("the manifest's implementation_version is what the loader and the layer itself report",
          "[integration][loader]") {
  Fixture f;
  // The library the loader loaded, and the manifest next to it that named it (the build tree's).
  Dl_info info{};
  REQUIRE(dladdr(reinterpret_cast<void*>(vkGetDeviceProcAddr(f.device().handle(), "vkCmdBuildAccelerationStructuresKHR")),
                 &info));
  REQUIRE(info.dli_fname);
  const std::string library = info.dli_fname;
  const std::string manifest_path = library.substr(0, library.rfind('/') + 1) + "VkLayer_asval_as_validation.json";
  std::ifstream in(manifest_path);
  REQUIRE(in);
  const std::string text = nlohmann::json::parse(in)["layer"]["implementation_version"].get<std::string>();
  INFO(manifest_path << ": implementation_version \"" << text << "\"");
  // The loader reads the string with atoi: only a plain decimal number means what it says.
  REQUIRE(!text.empty());
  REQUIRE(text.find_first_not_of("0123456789") == std::string::npos);
  const uint32_t version = static_cast<uint32_t>(std::stoul(text));

  // What the loader answers (from the manifest).
  uint32_t count = 0;
  REQUIRE(vkEnumerateInstanceLayerProperties(&count, nullptr) == VK_SUCCESS);
  std::vector<VkLayerProperties> layers(count);
  REQUIRE(vkEnumerateInstanceLayerProperties(&count, layers.data()) == VK_SUCCESS);
  CHECK(FindAsval(layers).implementationVersion == version);

  // What the layer answers itself (compiled in): its exported introspection function.
  void* handle = dlopen(library.c_str(), RTLD_NOW | RTLD_NOLOAD);
  REQUIRE(handle);
  auto own = reinterpret_cast<PFN_vkEnumerateInstanceLayerProperties>(dlsym(handle, "vkEnumerateInstanceLayerProperties"));
  REQUIRE(own);
  count = 1;
  VkLayerProperties props{};
  CHECK(own(&count, &props) == VK_SUCCESS);
  CHECK(std::string(props.layerName) == "VK_LAYER_ASVAL_as_validation");
  CHECK(props.implementationVersion == version);
  dlclose(handle);
}

TEST_CASE("intercepted commands resolve into the layer, aliases included", "[integration][loader]") {
  Fixture f;
  VkInstance instance = f.instance().handle();
  VkDevice device = f.device().handle();

  // Through vkGetInstanceProcAddr the loader hands out its trampoline for device commands: only non-null.
  CHECK(vkGetInstanceProcAddr(instance, "vkCmdBuildAccelerationStructuresKHR") != nullptr);
  CHECK(InsideLayer(vkGetDeviceProcAddr(device, "vkCmdBuildAccelerationStructuresKHR")));
  CHECK(InsideLayer(vkGetDeviceProcAddr(device, "vkCreateAccelerationStructureKHR")));
  // A promoted command and its extension alias both reach the same hook.
  PFN_vkVoidFunction core = vkGetDeviceProcAddr(device, "vkBindBufferMemory2");
  PFN_vkVoidFunction khr = vkGetDeviceProcAddr(device, "vkBindBufferMemory2KHR");
  CHECK(InsideLayer(core));
  // The KHR name is only offered when the chain below offers it (VK_KHR_bind_memory2 is core in 1.1: the
  // loader may or may not answer); when offered, it must be the layer's hook.
  if (khr) CHECK(khr == core);
}

TEST_CASE("other commands pass through, unavailable ones stay null", "[integration][loader]") {
  Fixture f;
  VkDevice device = f.device().handle();
  PFN_vkVoidFunction viewport = vkGetDeviceProcAddr(device, "vkCmdSetViewport");
  CHECK(viewport != nullptr);
  CHECK_FALSE(InsideLayer(viewport));
  // VK_EXT_mesh_shader is not enabled on the test device: nobody in the chain offers it (the layer's hook for it,
  // family traces, is not handed out either).
  CHECK(vkGetDeviceProcAddr(device, "vkCmdDrawMeshTasksEXT") == nullptr);
  CHECK(vkGetDeviceProcAddr(device, "vkNotACommand") == nullptr);
  CHECK(f.monitor().Verify() == "");
}

}  // namespace
}  // namespace asval_test
