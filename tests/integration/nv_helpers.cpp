#include "nv_helpers.h"

#include <cstdlib>
#include <cstring>
#include <stdexcept>

namespace asval_test {

namespace {

template <typename T>
T Load(VkDevice device, const char* name) {
  auto fn = reinterpret_cast<T>(vkGetDeviceProcAddr(device, name));
  if (!fn) throw std::runtime_error(std::string(name) + " is not available (VK_NV_ray_tracing not enabled?)");
  return fn;
}

constexpr VkDeviceSize kVerticesOffset = 0;
constexpr VkDeviceSize kIndicesOffset = 256;
constexpr VkDeviceSize kAabbsOffset = 512;
constexpr uint32_t kVertexCount = 16;

uint32_t FirstMemoryType(uint32_t bits) {
  for (uint32_t i = 0; i < 32; ++i) {
    if (bits & (1u << i)) return i;
  }
  throw std::runtime_error("no memory type for the structure");
}

}  // namespace

NvDriver::NvDriver() {
  const char* native = std::getenv("ASVAL_TEST_NV_NATIVE");
  if (!native || std::string(native) != "1") test_driver_.emplace();
}

vkkit::DeviceOptions NvRayTracing() {
  vkkit::DeviceOptions options;
  options.extensions.push_back(VK_NV_RAY_TRACING_EXTENSION_NAME);
  return options;
}

NvProcs::NvProcs(VkDevice device)
    : Create(Load<PFN_vkCreateAccelerationStructureNV>(device, "vkCreateAccelerationStructureNV")),
      Destroy(Load<PFN_vkDestroyAccelerationStructureNV>(device, "vkDestroyAccelerationStructureNV")),
      Requirements(Load<PFN_vkGetAccelerationStructureMemoryRequirementsNV>(
          device, "vkGetAccelerationStructureMemoryRequirementsNV")),
      Bind(Load<PFN_vkBindAccelerationStructureMemoryNV>(device, "vkBindAccelerationStructureMemoryNV")),
      Handle(Load<PFN_vkGetAccelerationStructureHandleNV>(device, "vkGetAccelerationStructureHandleNV")),
      CmdBuild(Load<PFN_vkCmdBuildAccelerationStructureNV>(device, "vkCmdBuildAccelerationStructureNV")),
      CmdCopy(Load<PFN_vkCmdCopyAccelerationStructureNV>(device, "vkCmdCopyAccelerationStructureNV")),
      CmdWriteProperties(Load<PFN_vkCmdWriteAccelerationStructuresPropertiesNV>(
          device, "vkCmdWriteAccelerationStructuresPropertiesNV")) {}

vkkit::Buffer NvBuffer(vkkit::Device& device, VkDeviceSize size, VkBufferUsageFlags usage) {
  return device.CreateBuffer(size, usage);
}

NvInputs::NvInputs(vkkit::Device& device) : device_(device) {
  buffer_ = NvBuffer(device, 1024);
  auto* bytes = static_cast<unsigned char*>(buffer_.mapped);
  std::memset(bytes, 0, 1024);
  float vertices[kVertexCount * 3];
  for (uint32_t v = 0; v < kVertexCount; ++v) {
    const float corner[3][2] = {{0, 0}, {1, 0}, {0, 1}};
    vertices[3 * v + 0] = corner[v % 3][0];
    vertices[3 * v + 1] = corner[v % 3][1];
    vertices[3 * v + 2] = static_cast<float>(v / 3);
  }
  std::memcpy(bytes + kVerticesOffset, vertices, sizeof(vertices));
  const uint32_t indices[6] = {0, 1, 2, 3, 4, 5};
  std::memcpy(bytes + kIndicesOffset, indices, sizeof(indices));
  const float aabbs[2][6] = {{0, 0, 0, 1, 1, 1}, {2, 0, 0, 3, 1, 1}};
  std::memcpy(bytes + kAabbsOffset, aabbs, sizeof(aabbs));
}

NvInputs::~NvInputs() { device_.Destroy(buffer_); }

VkGeometryNV NvInputs::Triangles(uint32_t triangles, bool indexed) const {
  VkGeometryNV g{VK_STRUCTURE_TYPE_GEOMETRY_NV};
  g.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_NV;
  g.flags = VK_GEOMETRY_OPAQUE_BIT_NV;
  g.geometry.triangles.sType = VK_STRUCTURE_TYPE_GEOMETRY_TRIANGLES_NV;
  g.geometry.triangles.vertexData = buffer_.buffer;
  g.geometry.triangles.vertexOffset = kVerticesOffset;
  g.geometry.triangles.vertexCount = indexed ? kVertexCount : 3 * triangles;
  g.geometry.triangles.vertexStride = 12;
  g.geometry.triangles.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
  g.geometry.triangles.indexType = indexed ? VK_INDEX_TYPE_UINT32 : VK_INDEX_TYPE_NONE_NV;
  if (indexed) {
    g.geometry.triangles.indexData = buffer_.buffer;
    g.geometry.triangles.indexOffset = kIndicesOffset;
    g.geometry.triangles.indexCount = 3 * triangles;
  }
  g.geometry.aabbs.sType = VK_STRUCTURE_TYPE_GEOMETRY_AABB_NV;
  return g;
}

VkGeometryNV NvInputs::Aabbs(uint32_t count) const {
  VkGeometryNV g{VK_STRUCTURE_TYPE_GEOMETRY_NV};
  g.geometryType = VK_GEOMETRY_TYPE_AABBS_NV;
  g.flags = VK_GEOMETRY_OPAQUE_BIT_NV;
  g.geometry.triangles.sType = VK_STRUCTURE_TYPE_GEOMETRY_TRIANGLES_NV;
  g.geometry.aabbs.sType = VK_STRUCTURE_TYPE_GEOMETRY_AABB_NV;
  g.geometry.aabbs.aabbData = buffer_.buffer;
  g.geometry.aabbs.numAABBs = count;
  g.geometry.aabbs.stride = 24;
  g.geometry.aabbs.offset = kAabbsOffset;
  return g;
}

NvStructure::NvStructure(vkkit::Device& device, VkBuildAccelerationStructureFlagsNV flags,
                         std::vector<VkGeometryNV> geometries, Memory memory, const NvStructure* share)
    : device_(device), procs_(device.handle()), geometries_(std::move(geometries)) {
  info_.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_NV;
  info_.flags = flags;
  info_.geometryCount = static_cast<uint32_t>(geometries_.size());
  info_.pGeometries = geometries_.data();
  Create(memory, share);
}

NvStructure::NvStructure(vkkit::Device& device, VkBuildAccelerationStructureFlagsNV flags, uint32_t instances)
    : device_(device), procs_(device.handle()) {
  info_.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_NV;
  info_.flags = flags;
  info_.instanceCount = instances;
  Create(Memory::kOwn, nullptr);
}

void NvStructure::Create(Memory memory, const NvStructure* share) {
  VkAccelerationStructureCreateInfoNV create{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_NV};
  create.info = info_;
  vkkit::Check(procs_.Create(device_.handle(), &create, nullptr, &handle_), "vkCreateAccelerationStructureNV");
  if (memory == Memory::kUnbound) return;
  VkDeviceSize offset = 0;
  if (share) {
    bound_ = share->bound_;
  } else {
    VkAccelerationStructureMemoryRequirementsInfoNV info{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_INFO_NV};
    info.type = VK_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_TYPE_OBJECT_NV;
    info.accelerationStructure = handle_;
    VkMemoryRequirements2 requirements{VK_STRUCTURE_TYPE_MEMORY_REQUIREMENTS_2};
    procs_.Requirements(device_.handle(), &info, &requirements);
    VkMemoryAllocateInfo allocate{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    allocate.allocationSize = requirements.memoryRequirements.size;
    allocate.memoryTypeIndex = FirstMemoryType(requirements.memoryRequirements.memoryTypeBits);
    vkkit::Check(vkAllocateMemory(device_.handle(), &allocate, nullptr, &memory_), "vkAllocateMemory");
    bound_ = memory_;
  }
  VkBindAccelerationStructureMemoryInfoNV bind{VK_STRUCTURE_TYPE_BIND_ACCELERATION_STRUCTURE_MEMORY_INFO_NV};
  bind.accelerationStructure = handle_;
  bind.memory = bound_;
  bind.memoryOffset = offset;
  vkkit::Check(procs_.Bind(device_.handle(), 1, &bind), "vkBindAccelerationStructureMemoryNV");
}

NvStructure::~NvStructure() {
  procs_.Destroy(device_.handle(), handle_, nullptr);
  if (memory_) vkFreeMemory(device_.handle(), memory_, nullptr);
}

VkDeviceSize NvStructure::Requirement(VkAccelerationStructureMemoryRequirementsTypeNV type) const {
  VkAccelerationStructureMemoryRequirementsInfoNV info{
      VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_INFO_NV};
  info.type = type;
  info.accelerationStructure = handle_;
  VkMemoryRequirements2 requirements{VK_STRUCTURE_TYPE_MEMORY_REQUIREMENTS_2};
  procs_.Requirements(device_.handle(), &info, &requirements);
  return requirements.memoryRequirements.size;
}

uint64_t NvStructure::Reference() const {
  uint64_t reference = 0;
  vkkit::Check(procs_.Handle(device_.handle(), handle_, sizeof(reference), &reference),
               "vkGetAccelerationStructureHandleNV");
  return reference;
}

VkAccelerationStructureInstanceNV NvStructure::Instance(uint32_t i) const {
  VkAccelerationStructureInstanceNV instance{};
  instance.transform.matrix[0][0] = instance.transform.matrix[1][1] = instance.transform.matrix[2][2] = 1.0f;
  instance.transform.matrix[0][3] = 4.0f * static_cast<float>(i);
  instance.mask = 0xff;
  instance.accelerationStructureReference = Reference();
  return instance;
}

VkResult RunCommands(Commands& commands, const std::function<void(VkCommandBuffer)>& record) {
  VkCommandBuffer cb = commands.Begin();
  record(cb);
  commands.End(cb);
  return commands.Submit(cb);
}

VkResult RunCommands(vkkit::Device& device, const std::function<void(Commands&, VkCommandBuffer)>& record) {
  Commands commands(device);
  return RunCommands(commands, [&](VkCommandBuffer cb) { record(commands, cb); });
}

void CmdBuildNV(vkkit::Device& device, VkCommandBuffer cb, const NvStructure& dst, VkBuffer scratch, bool update,
                const NvStructure* src, const VkAccelerationStructureInfoNV* info, VkBuffer instance_data) {
  const NvProcs procs(device.handle());
  procs.CmdBuild(cb, info ? info : &dst.info(), instance_data, 0, update ? VK_TRUE : VK_FALSE, dst.handle(),
                 src ? src->handle() : VK_NULL_HANDLE, scratch, 0);
}

}  // namespace asval_test
