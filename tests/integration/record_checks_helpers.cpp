#include "record_checks_helpers.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace asval_test {

namespace {

constexpr VkDeviceSize kScratchSize = VkDeviceSize{4} << 20;
constexpr VkDeviceSize kScratchSlice = 128;  // what real apps align every slice to
constexpr uint32_t kMaxGeometriesWithCounts = 1u << 16;

ApiSettings* Narrowed(ApiSettings& settings, const char* families) {
  if (!families) return nullptr;
  settings.Add("enabled_checks", families);
  return &settings;
}

template <typename T>
T Load(vkkit::Device& device, const char* name) {
  auto fn = reinterpret_cast<T>(vkGetDeviceProcAddr(device.handle(), name));
  if (!fn) throw std::runtime_error(std::string(name) + " is not available");
  return fn;
}

}  // namespace

CheckFixture::CheckFixture(const char* families, const vkkit::DeviceOptions& device) {
  ApiSettings* settings = Narrowed(settings_, families);
  fixture_ = std::make_unique<Fixture>(settings ? settings->Chain() : nullptr, device);
}

const char* CommandName(Command command) {
  switch (command) {
    case Command::kIndirect:
      return "vkCmdBuildAccelerationStructuresIndirectKHR";
    case Command::kHost:
      return "vkBuildAccelerationStructuresKHR";
    case Command::kDirect:
      break;
  }
  return "vkCmdBuildAccelerationStructuresKHR";
}

const char* PerCommand::For(Command command) const {
  switch (command) {
    case Command::kIndirect:
      return indirect;
    case Command::kHost:
      return host;
    case Command::kDirect:
      break;
  }
  return direct;
}

void Issue(vkkit::Device& device, Command command, const std::vector<VkAccelerationStructureBuildGeometryInfoKHR>& infos,
           const std::vector<const VkAccelerationStructureBuildRangeInfoKHR*>& ranges, IndirectArgs indirect_args) {
  const auto count = static_cast<uint32_t>(infos.size());
  switch (command) {
    case Command::kDirect:
      device.OneShot([&](VkCommandBuffer cb) { device.CmdBuildAccelerationStructuresKHR(cb, count, infos.data(),
                                                                                        ranges.data()); },
                     /*submit=*/false);
      return;
    case Command::kIndirect: {
      auto indirect = Load<PFN_vkCmdBuildAccelerationStructuresIndirectKHR>(
          device, "vkCmdBuildAccelerationStructuresIndirectKHR");
      std::vector<VkDeviceAddress> addresses(count, indirect_args.address);
      std::vector<uint32_t> strides(count, indirect_args.stride);
      std::vector<std::vector<uint32_t>> max_counts(count);
      std::vector<const uint32_t*> max_count_pointers(count);
      for (uint32_t i = 0; i < count; ++i) {
        // A test of an absurd geometry count (over maxGeometryCount) gets no max-count array: only the
        // structure family runs then, and it reads none.
        if (infos[i].geometryCount > kMaxGeometriesWithCounts) continue;
        for (uint32_t j = 0; j < infos[i].geometryCount; ++j) {
          max_counts[i].push_back(ranges[i] ? ranges[i][j].primitiveCount : 1);
        }
        max_count_pointers[i] = max_counts[i].data();
      }
      device.OneShot([&](VkCommandBuffer cb) { indirect(cb, count, infos.data(), addresses.data(), strides.data(),
                                                        max_count_pointers.data()); },
                     /*submit=*/false);
      return;
    }
    case Command::kHost: {
      auto host = Load<PFN_vkBuildAccelerationStructuresKHR>(device, "vkBuildAccelerationStructuresKHR");
      host(device.handle(), VK_NULL_HANDLE, count, infos.data(), ranges.data());
      return;
    }
  }
}

void IssueOne(vkkit::Device& device, Command command, const VkAccelerationStructureBuildGeometryInfoKHR& info,
              const VkAccelerationStructureBuildRangeInfoKHR* ranges) {
  Issue(device, command, {info}, {ranges});
}

Scene::Scene(vkkit::Device& device) : device_(device) {
  inputs_ = device.CreateBuffer(kSize, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
  scratch_ = device.CreateBuffer(kScratchSize, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  auto* bytes = static_cast<uint8_t*>(inputs_.mapped);
  std::memset(bytes, 0, kSize);
  const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::memcpy(bytes + kVertices, positions, sizeof(positions));
  for (int v = 0; v < 3; ++v) std::memcpy(bytes + kWideVertices + 44 * v, positions + 3 * v, 12);
  const uint32_t indices32[3] = {0, 1, 2};
  const uint16_t indices16[3] = {0, 1, 2};
  std::memcpy(bytes + kIndices32, indices32, sizeof(indices32));
  std::memcpy(bytes + kIndices16, indices16, sizeof(indices16));
  const VkTransformMatrixKHR identity = {{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}}};
  std::memcpy(bytes + kTransforms, &identity, sizeof(identity));
  std::memcpy(bytes + kTransforms + 48, &identity, sizeof(identity));
  const VkAabbPositionsKHR boxes[2] = {{0, 0, 0, 1, 1, 1}, {2, 2, 2, 3, 3, 3}};
  for (int b = 0; b < 2; ++b) std::memcpy(bytes + kAabbs + 24 * b, &boxes[b], sizeof(VkAabbPositionsKHR));

  // The bottom-level structure the instances reference, built for real.
  VkAccelerationStructureGeometryKHR triangles = Triangles();
  VkAccelerationStructureBuildGeometryInfoKHR info = Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {triangles});
  info.pGeometries = &triangles;
  Prepare(info, {1});
  blas_.handle = info.dstAccelerationStructure;
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  BuildNow({info}, {&range});
  const VkAccelerationStructureDeviceAddressInfoKHR address_info{
      VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR, nullptr, blas_.handle};
  const VkDeviceAddress blas_address = device.GetAccelerationStructureDeviceAddressKHR(device.handle(), &address_info);
  for (int k = 0; k < 2; ++k) {
    VkAccelerationStructureInstanceKHR instance{};
    instance.transform = identity;
    instance.mask = 0xff;
    instance.accelerationStructureReference = blas_address;
    std::memcpy(bytes + kInstances + 64 * k, &instance, sizeof(instance));
    const VkDeviceAddress pointer = Address(kInstances + 64 * k);
    std::memcpy(bytes + kPointers + 8 * k, &pointer, sizeof(pointer));
  }
}

Scene::~Scene() {
  for (vkkit::AccelerationStructure& as : structures_) device_.Destroy(as);
  device_.Destroy(scratch_);
  device_.Destroy(inputs_);
}

VkAccelerationStructureGeometryKHR Scene::OnHost(VkAccelerationStructureGeometryKHR g) const {
  const auto to_host = [this](VkDeviceOrHostAddressConstKHR& a) {
    if (a.deviceAddress >= inputs_.address && a.deviceAddress < inputs_.address + kSize) {
      a.hostAddress = static_cast<const uint8_t*>(inputs_.mapped) + (a.deviceAddress - inputs_.address);
    }
  };
  switch (g.geometryType) {
    case VK_GEOMETRY_TYPE_TRIANGLES_KHR:
      to_host(g.geometry.triangles.vertexData);
      to_host(g.geometry.triangles.indexData);
      to_host(g.geometry.triangles.transformData);
      break;
    case VK_GEOMETRY_TYPE_AABBS_KHR:
      to_host(g.geometry.aabbs.data);
      break;
    case VK_GEOMETRY_TYPE_INSTANCES_KHR:
      to_host(g.geometry.instances.data);
      break;
    default:
      break;
  }
  return g;
}

VkAccelerationStructureGeometryKHR Scene::Triangles() const {
  VkAccelerationStructureGeometryKHR g{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  g.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
  g.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
  auto& tri = g.geometry.triangles;
  tri.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
  tri.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
  tri.vertexData.deviceAddress = Address(kVertices);
  tri.vertexStride = 12;
  tri.maxVertex = 2;
  tri.indexType = VK_INDEX_TYPE_NONE_KHR;
  return g;
}

VkAccelerationStructureGeometryKHR Scene::IndexedTriangles(VkIndexType type) const {
  VkAccelerationStructureGeometryKHR g = Triangles();
  g.geometry.triangles.indexType = type;
  g.geometry.triangles.indexData.deviceAddress = Address(type == VK_INDEX_TYPE_UINT16 ? kIndices16 : kIndices32);
  return g;
}

VkAccelerationStructureGeometryKHR Scene::Aabbs() const {
  VkAccelerationStructureGeometryKHR g{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  g.geometryType = VK_GEOMETRY_TYPE_AABBS_KHR;
  g.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
  g.geometry.aabbs.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_AABBS_DATA_KHR;
  g.geometry.aabbs.data.deviceAddress = Address(kAabbs);
  g.geometry.aabbs.stride = 24;
  return g;
}

VkAccelerationStructureGeometryKHR Scene::Instances(bool array_of_pointers) const {
  VkAccelerationStructureGeometryKHR g{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  g.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
  g.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
  g.geometry.instances.arrayOfPointers = array_of_pointers ? VK_TRUE : VK_FALSE;
  g.geometry.instances.data.deviceAddress = Address(array_of_pointers ? kPointers : kInstances);
  return g;
}

VkAccelerationStructureBuildGeometryInfoKHR Scene::Info(VkAccelerationStructureTypeKHR type,
                                                        const std::vector<VkAccelerationStructureGeometryKHR>& geometries) {
  VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  info.type = type;
  info.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR |
               VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR;
  info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  info.geometryCount = static_cast<uint32_t>(geometries.size());
  info.pGeometries = geometries.data();  // callers re-point it at storage that outlives the call
  return info;
}

void Scene::Prepare(VkAccelerationStructureBuildGeometryInfoKHR& info, const std::vector<uint32_t>& counts,
                    VkAccelerationStructureTypeKHR created_type) {
  VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
  device_.GetAccelerationStructureBuildSizesKHR(device_.handle(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR,
                                                &info, counts.data(), &sizes);
  const VkAccelerationStructureTypeKHR type =
      created_type == VK_ACCELERATION_STRUCTURE_TYPE_MAX_ENUM_KHR ? info.type : created_type;
  info.dstAccelerationStructure = NewStructure(type, sizes.accelerationStructureSize);
  const VkDeviceSize scratch = std::max(sizes.buildScratchSize, sizes.updateScratchSize);
  if (scratch_used_ + scratch > kScratchSize) throw std::runtime_error("Scene: scratch buffer exhausted");
  info.scratchData.deviceAddress = scratch_.address + scratch_used_;
  scratch_used_ += (scratch + kScratchSlice - 1) / kScratchSlice * kScratchSlice;
}

VkAccelerationStructureKHR Scene::NewStructure(VkAccelerationStructureTypeKHR type, VkDeviceSize size) {
  structures_.push_back(device_.CreateAccelerationStructure(type, size));
  return structures_.back().handle;
}

void Scene::BuildNow(const std::vector<VkAccelerationStructureBuildGeometryInfoKHR>& infos,
                     const std::vector<const VkAccelerationStructureBuildRangeInfoKHR*>& ranges) {
  device_.OneShot([&](VkCommandBuffer cb) {
    device_.CmdBuildAccelerationStructuresKHR(cb, static_cast<uint32_t>(infos.size()), infos.data(), ranges.data());
  });
}

std::vector<VkAccelerationStructureBuildRangeInfoKHR> Ranges(size_t geometries, uint32_t count) {
  return std::vector<VkAccelerationStructureBuildRangeInfoKHR>(geometries, VkAccelerationStructureBuildRangeInfoKHR{
                                                                               count, 0, 0, 0});
}

uint32_t ComputeQueueFamily(VkPhysicalDevice gpu) {
  uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(gpu, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(gpu, &count, families.data());
  for (uint32_t i = 0; i < count; ++i) {
    if (families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) return i;
  }
  return 0;
}

FeaturelessDevice::FeaturelessDevice(VkPhysicalDevice gpu) {
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queue{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queue.queueFamilyIndex = ComputeQueueFamily(gpu);
  queue.queueCount = 1;
  queue.pQueuePriorities = &priority;
  VkPhysicalDeviceVulkan12Features v12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  v12.bufferDeviceAddress = VK_TRUE;
  const char* extensions[] = {VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME,
                              VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME};
  VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &v12};
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &queue;
  info.enabledExtensionCount = 2;
  info.ppEnabledExtensionNames = extensions;
  vkkit::Check(vkCreateDevice(gpu, &info, nullptr, &device_), "vkCreateDevice");
  VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool_info.queueFamilyIndex = queue.queueFamilyIndex;
  vkkit::Check(vkCreateCommandPool(device_, &pool_info, nullptr, &pool_), "vkCreateCommandPool");
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = pool_;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  vkkit::Check(vkAllocateCommandBuffers(device_, &alloc, &cb_), "vkAllocateCommandBuffers");
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  vkkit::Check(vkBeginCommandBuffer(cb_, &begin), "vkBeginCommandBuffer");
  CmdBuild = reinterpret_cast<PFN_vkCmdBuildAccelerationStructuresKHR>(
      vkGetDeviceProcAddr(device_, "vkCmdBuildAccelerationStructuresKHR"));
}

FeaturelessDevice::~FeaturelessDevice() {
  vkEndCommandBuffer(cb_);
  vkDestroyCommandPool(device_, pool_, nullptr);
  vkDestroyDevice(device_, nullptr);
}

}  // namespace asval_test
