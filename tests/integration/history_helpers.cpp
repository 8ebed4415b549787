#include "history_helpers.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace asval_test {

namespace {

template <typename T>
T Load(vkkit::Device& device, const char* name) {
  return reinterpret_cast<T>(vkGetDeviceProcAddr(device.handle(), name));
}

// The queue family of vkkit::Device's queue (the first with compute): lavapipe has exactly one, index 0.
constexpr uint32_t kQueueFamily = 0;

constexpr VkBufferUsageFlags kInputUsage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR;

}  // namespace

HistoryFixture::HistoryFixture(const char* families, const std::vector<std::pair<const char*, const char*>>& settings,
                               const vkkit::DeviceOptions& device) {
  if (families) settings_.Add("enabled_checks", families);
  for (const auto& [name, value] : settings) settings_.Add(name, value);
  fixture_ = std::make_unique<Fixture>(settings_.settings.empty() ? nullptr : settings_.Chain(), device);
}

Procs::Procs(vkkit::Device& device) {
  CmdBuild = Load<PFN_vkCmdBuildAccelerationStructuresKHR>(device, "vkCmdBuildAccelerationStructuresKHR");
  HostBuild = Load<PFN_vkBuildAccelerationStructuresKHR>(device, "vkBuildAccelerationStructuresKHR");
  CmdCopy = Load<PFN_vkCmdCopyAccelerationStructureKHR>(device, "vkCmdCopyAccelerationStructureKHR");
  CmdCopyToMemory =
      Load<PFN_vkCmdCopyAccelerationStructureToMemoryKHR>(device, "vkCmdCopyAccelerationStructureToMemoryKHR");
  CmdCopyMemoryTo =
      Load<PFN_vkCmdCopyMemoryToAccelerationStructureKHR>(device, "vkCmdCopyMemoryToAccelerationStructureKHR");
  CmdWriteProperties =
      Load<PFN_vkCmdWriteAccelerationStructuresPropertiesKHR>(device, "vkCmdWriteAccelerationStructuresPropertiesKHR");
  HostCopy = Load<PFN_vkCopyAccelerationStructureKHR>(device, "vkCopyAccelerationStructureKHR");
  HostWriteProperties =
      Load<PFN_vkWriteAccelerationStructuresPropertiesKHR>(device, "vkWriteAccelerationStructuresPropertiesKHR");
  CmdExecuteCommands = Load<PFN_vkCmdExecuteCommands>(device, "vkCmdExecuteCommands");
  QueueSubmit2 = Load<PFN_vkQueueSubmit2>(device, "vkQueueSubmit2");
}

VkResult Procs::Submit2(VkQueue queue, VkCommandBuffer cb) const {
  VkCommandBufferSubmitInfo cb_info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
  cb_info.commandBuffer = cb;
  VkSubmitInfo2 submit{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
  submit.commandBufferInfoCount = 1;
  submit.pCommandBufferInfos = &cb_info;
  return QueueSubmit2(queue, 1, &submit, VK_NULL_HANDLE);
}

// ---- Commands --------------------------------------------------------------------------------------------------

Commands::Commands(vkkit::Device& device) : device_(device) {
  VkCommandPoolCreateInfo info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  info.queueFamilyIndex = kQueueFamily;
  vkkit::Check(vkCreateCommandPool(device.handle(), &info, nullptr, &pool_), "vkCreateCommandPool");
}

// Nothing is pending here: Submit waits for the queue (and skipped submissions never ran). Not waiting again
// keeps the destructors off the queue, which threads share under the app's lock only.
Commands::~Commands() {
  if (!buffers_.empty()) {
    vkFreeCommandBuffers(device_.handle(), pool_, static_cast<uint32_t>(buffers_.size()), buffers_.data());
  }
  vkDestroyCommandPool(device_.handle(), pool_, nullptr);
}

VkCommandBuffer Commands::Begin() {
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = pool_;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  VkCommandBuffer cb = VK_NULL_HANDLE;
  vkkit::Check(vkAllocateCommandBuffers(device_.handle(), &alloc, &cb), "vkAllocateCommandBuffers");
  buffers_.push_back(cb);
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  vkkit::Check(vkBeginCommandBuffer(cb, &begin), "vkBeginCommandBuffer");
  return cb;
}

VkCommandBuffer Commands::BeginSecondary(VkCommandBufferUsageFlags flags) {
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = pool_;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_SECONDARY;
  alloc.commandBufferCount = 1;
  VkCommandBuffer cb = VK_NULL_HANDLE;
  vkkit::Check(vkAllocateCommandBuffers(device_.handle(), &alloc, &cb), "vkAllocateCommandBuffers");
  buffers_.push_back(cb);
  VkCommandBufferInheritanceInfo inheritance{VK_STRUCTURE_TYPE_COMMAND_BUFFER_INHERITANCE_INFO};
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = flags;
  begin.pInheritanceInfo = &inheritance;
  vkkit::Check(vkBeginCommandBuffer(cb, &begin), "vkBeginCommandBuffer");
  return cb;
}

void Commands::End(VkCommandBuffer cb) { vkkit::Check(vkEndCommandBuffer(cb), "vkEndCommandBuffer"); }

void Commands::Barrier(VkCommandBuffer cb) {
  VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  barrier.srcAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;
  barrier.dstAccessMask =
      VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR | VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                       VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, 0, 1, &barrier, 0, nullptr, 0, nullptr);
}

VkResult Commands::Submit(const std::vector<VkCommandBuffer>& cbs) {
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = static_cast<uint32_t>(cbs.size());
  submit.pCommandBuffers = cbs.data();
  const VkResult result = vkQueueSubmit(device_.queue(), 1, &submit, VK_NULL_HANDLE);
  if (result == VK_SUCCESS) vkkit::Check(vkQueueWaitIdle(device_.queue()), "vkQueueWaitIdle");
  return result;
}

// ---- Inputs ----------------------------------------------------------------------------------------------------

Inputs::Inputs(vkkit::Device& device, VkBufferUsageFlags extra_usage) : device_(device) {
  buffer_ = device.CreateBuffer(1024, kInputUsage | extra_usage);
  auto* bytes = static_cast<unsigned char*>(buffer_.mapped);
  std::memset(bytes, 0, 1024);
  float vertices[kVertexCount * 3];
  for (uint32_t v = 0; v < kVertexCount; ++v) {
    // Triangles (3k, 3k+1, 3k+2) are unit right triangles moved along z: none is degenerate.
    const float corner[3][2] = {{0, 0}, {1, 0}, {0, 1}};
    vertices[3 * v + 0] = corner[v % 3][0];
    vertices[3 * v + 1] = corner[v % 3][1];
    vertices[3 * v + 2] = static_cast<float>(v / 3);
  }
  std::memcpy(bytes + kVerticesOffset, vertices, sizeof(vertices));
  uint32_t indices[kMaxTriangles * 3];
  for (uint32_t i = 0; i < kMaxTriangles * 3; ++i) indices[i] = i;
  std::memcpy(bytes + kIndicesOffset, indices, sizeof(indices));
  const float transform[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
  std::memcpy(bytes + kTransformOffset, transform, sizeof(transform));
  const float aabbs[kMaxTriangles][6] = {{0, 0, 0, 1, 1, 1}, {2, 0, 0, 3, 1, 1}};
  std::memcpy(bytes + kAabbsOffset, aabbs, sizeof(aabbs));
}

Inputs::~Inputs() { device_.Destroy(buffer_); }

BuildInfo MakeBuildInfo(const Shape& shape, const Inputs& inputs) {
  BuildInfo b;
  b.geometries.resize(shape.geometries);
  b.ranges.resize(shape.geometries);
  for (uint32_t j = 0; j < shape.geometries; ++j) {
    VkAccelerationStructureGeometryKHR& g = b.geometries[j];
    g.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR;
    g.geometryType = shape.geometry_type;
    g.flags = shape.geometry_flags;
    if (shape.geometry_type == VK_GEOMETRY_TYPE_AABBS_KHR) {
      auto& a = g.geometry.aabbs;
      a.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_AABBS_DATA_KHR;
      a.data.deviceAddress = inputs.aabbs();
      a.stride = 24;
    } else {
      auto& t = g.geometry.triangles;
      t.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
      t.vertexFormat = shape.vertex_format;
      t.vertexData.deviceAddress = inputs.vertices();
      t.vertexStride = shape.vertex_stride;
      t.maxVertex = shape.max_vertex ? shape.max_vertex : 3 * shape.triangles - 1;
      t.indexType = shape.index_type;
      if (shape.index_type != VK_INDEX_TYPE_NONE_KHR) t.indexData.deviceAddress = inputs.indices();
      if (shape.transform) t.transformData.deviceAddress = inputs.transform();
    }
    b.ranges[j].primitiveCount = shape.triangles;
    b.ranges[j].primitiveOffset = shape.primitive_offset;
    b.ranges[j].firstVertex = shape.first_vertex;
  }
  b.info.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR;
  b.info.type = shape.type;
  b.info.flags = shape.flags;
  b.info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  b.info.geometryCount = shape.geometries;
  b.info.pGeometries = b.geometries.data();
  b.range_pointer = b.ranges.data();
  return b;
}

// ---- Blas ------------------------------------------------------------------------------------------------------

namespace {

// Sizes for the largest shape of either geometry type, doubled: every Shape of the tests fits.
VkAccelerationStructureBuildSizesInfoKHR LargestSizes(vkkit::Device& device, const Inputs& inputs) {
  VkAccelerationStructureBuildSizesInfoKHR largest{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
  for (VkGeometryTypeKHR type : {VK_GEOMETRY_TYPE_TRIANGLES_KHR, VK_GEOMETRY_TYPE_AABBS_KHR}) {
    Shape shape;
    shape.geometries = Inputs::kMaxGeometries;
    shape.triangles = Inputs::kMaxTriangles;
    shape.geometry_type = type;
    shape.index_type = VK_INDEX_TYPE_UINT32;
    shape.transform = true;
    BuildInfo b = MakeBuildInfo(shape, inputs);
    std::vector<uint32_t> counts(shape.geometries, shape.triangles);
    VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
    device.GetAccelerationStructureBuildSizesKHR(device.handle(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR,
                                                 &b.info, counts.data(), &sizes);
    largest.accelerationStructureSize = std::max(largest.accelerationStructureSize, sizes.accelerationStructureSize);
    largest.buildScratchSize = std::max(largest.buildScratchSize, sizes.buildScratchSize);
    largest.updateScratchSize = std::max(largest.updateScratchSize, sizes.updateScratchSize);
  }
  return largest;
}

}  // namespace

Blas::Blas(vkkit::Device& device, const Inputs& inputs, const Blas* shared, VkDeviceSize offset)
    : device_(device), procs_(device), inputs_(&inputs), offset_(offset) {
  const VkAccelerationStructureBuildSizesInfoKHR sizes = LargestSizes(device, inputs);
  size_ = (sizes.accelerationStructureSize * 2 + 255) & ~VkDeviceSize{255};
  if (shared) {
    storage_buffer_ = shared->storage_buffer_;
    size_ = shared->size_;
  } else {
    storage_ = device.CreateBuffer(size_, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR);
    storage_buffer_ = storage_.buffer;
  }
  scratch_ = device.CreateBuffer(std::max(sizes.buildScratchSize, sizes.updateScratchSize) * 2 + 256,
                                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  Create();
}

void Blas::Create() {
  VkAccelerationStructureCreateInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
  info.buffer = storage_buffer_;
  info.offset = offset_;
  info.size = size_ - offset_;
  info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  vkkit::Check(device_.CreateAccelerationStructureKHR(device_.handle(), &info, nullptr, &handle_),
               "vkCreateAccelerationStructureKHR");
  VkAccelerationStructureDeviceAddressInfoKHR address{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR};
  address.accelerationStructure = handle_;
  address_ = device_.GetAccelerationStructureDeviceAddressKHR(device_.handle(), &address);
}

Blas::~Blas() {
  if (handle_) device_.DestroyAccelerationStructureKHR(device_.handle(), handle_, nullptr);
  device_.Destroy(scratch_);
  device_.Destroy(storage_);
}

void Blas::Recreate() {
  device_.DestroyAccelerationStructureKHR(device_.handle(), handle_, nullptr);
  handle_ = VK_NULL_HANDLE;
  Create();
}

void Blas::DestroyHandle() {
  if (handle_) device_.DestroyAccelerationStructureKHR(device_.handle(), handle_, nullptr);
  handle_ = VK_NULL_HANDLE;
}

void Blas::DestroyStorageBuffer() {
  if (storage_.buffer) vkDestroyBuffer(device_.handle(), storage_.buffer, nullptr);
  storage_.buffer = VK_NULL_HANDLE;  // ~Blas frees the memory only
}

void Blas::FreeStorageMemory() {
  if (storage_.memory) vkFreeMemory(device_.handle(), storage_.memory, nullptr);
  storage_.memory = VK_NULL_HANDLE;  // ~Blas destroys the buffer only
}

VkAccelerationStructureKHR Blas::Relocate() {
  if (!storage_.memory) throw std::logic_error("Blas::Relocate needs a structure with storage of its own");
  const VkAccelerationStructureKHR old = handle_;
  if (storage_.buffer) vkDestroyBuffer(device_.handle(), storage_.buffer, nullptr);
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = size_;
  info.usage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
  vkkit::Check(vkCreateBuffer(device_.handle(), &info, nullptr, &storage_.buffer), "vkCreateBuffer");
  vkkit::Check(vkBindBufferMemory(device_.handle(), storage_.buffer, storage_.memory, 0), "vkBindBufferMemory");
  storage_buffer_ = storage_.buffer;
  handle_ = VK_NULL_HANDLE;
  Create();
  return old;
}

BuildInfo Blas::Info(const Shape& shape, VkBuildAccelerationStructureModeKHR mode) const {
  BuildInfo b = MakeBuildInfo(shape, *inputs_);
  b.info.mode = mode;
  b.info.srcAccelerationStructure = mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR ? handle_ : VK_NULL_HANDLE;
  b.info.dstAccelerationStructure = handle_;
  b.info.scratchData.deviceAddress = scratch_.address;
  return b;
}

void Blas::Record(VkCommandBuffer cb, const Shape& shape, VkBuildAccelerationStructureModeKHR mode,
                  VkAccelerationStructureKHR src) {
  BuildInfo b = Info(shape, mode);
  b.info.srcAccelerationStructure = src;
  procs_.CmdBuild(cb, 1, &b.info, &b.range_pointer);
}

void Blas::Build(VkCommandBuffer cb, const Shape& shape) {
  Record(cb, shape, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR, VK_NULL_HANDLE);
}

void Blas::Update(VkCommandBuffer cb, const Shape& shape, const Blas* src) {
  Record(cb, shape, VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR, src ? src->handle_ : handle_);
}

VkResult Blas::HostUpdate(const Shape& shape) {
  if (!procs_.HostBuild) throw std::runtime_error("vkBuildAccelerationStructuresKHR is not available");
  BuildInfo b = MakeBuildInfo(shape, *inputs_);
  b.info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
  b.info.srcAccelerationStructure = handle_;
  b.info.dstAccelerationStructure = handle_;
  b.info.scratchData.hostAddress = scratch_.mapped;
  return procs_.HostBuild(device_.handle(), VK_NULL_HANDLE, 1, &b.info, &b.range_pointer);
}

// ---- Tlas ------------------------------------------------------------------------------------------------------

Tlas::Tlas(vkkit::Device& device, uint32_t max_instances) : device_(device), procs_(device) {
  VkAccelerationStructureGeometryKHR geometry{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  geometry.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
  geometry.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
  VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  info.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
  info.flags = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR;
  info.geometryCount = 1;
  info.pGeometries = &geometry;
  VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
  device.GetAccelerationStructureBuildSizesKHR(device.handle(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &info,
                                               &max_instances, &sizes);
  as_ = device.CreateAccelerationStructure(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR,
                                           (sizes.accelerationStructureSize + 255) & ~VkDeviceSize{255});
  scratch_ = device.CreateBuffer(std::max(sizes.buildScratchSize, sizes.updateScratchSize) + 256,
                                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
}

Tlas::~Tlas() {
  device_.Destroy(as_);
  device_.Destroy(scratch_);
}

VkDeviceAddress Tlas::address() const {
  VkAccelerationStructureDeviceAddressInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR};
  info.accelerationStructure = as_.handle;
  return device_.GetAccelerationStructureDeviceAddressKHR(device_.handle(), &info);
}

void Tlas::DestroyHandle() {
  if (as_.handle) device_.DestroyAccelerationStructureKHR(device_.handle(), as_.handle, nullptr);
  as_.handle = VK_NULL_HANDLE;
}

void Tlas::DestroyStorageBuffer() {
  if (as_.storage.buffer) vkDestroyBuffer(device_.handle(), as_.storage.buffer, nullptr);
  as_.storage.buffer = VK_NULL_HANDLE;  // ~Tlas frees the memory only
}

void Tlas::FreeStorageMemory() {
  if (as_.storage.memory) vkFreeMemory(device_.handle(), as_.storage.memory, nullptr);
  as_.storage.memory = VK_NULL_HANDLE;  // ~Tlas destroys the buffer only
}

VkAccelerationStructureInstanceKHR InstanceRecord(VkDeviceAddress reference, uint32_t i) {
  VkAccelerationStructureInstanceKHR instance{};
  instance.transform.matrix[0][0] = instance.transform.matrix[1][1] = instance.transform.matrix[2][2] = 1.0f;
  instance.transform.matrix[0][3] = static_cast<float>(i) * 4.0f;
  instance.mask = 0xff;
  instance.accelerationStructureReference = reference;
  return instance;
}

vkkit::Buffer Tlas::MakeInstances(const std::vector<const Blas*>& blases) {
  const size_t count = std::max<size_t>(1, blases.size());
  vkkit::Buffer buffer = device_.CreateBuffer(sizeof(VkAccelerationStructureInstanceKHR) * count, kInputUsage);
  for (size_t i = 0; i < blases.size(); ++i) {
    const VkAccelerationStructureInstanceKHR instance = InstanceRecord(blases[i]->address(), static_cast<uint32_t>(i));
    std::memcpy(static_cast<unsigned char*>(buffer.mapped) + i * sizeof(instance), &instance, sizeof(instance));
  }
  return buffer;
}

BuildInfo Tlas::Info(const vkkit::Buffer& instances, uint32_t count, VkBuildAccelerationStructureModeKHR mode) const {
  BuildInfo b;
  VkAccelerationStructureGeometryKHR& geometry =
      b.geometries.emplace_back(VkAccelerationStructureGeometryKHR{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR});
  geometry.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
  geometry.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
  geometry.geometry.instances.data.deviceAddress = instances.address;
  VkAccelerationStructureBuildGeometryInfoKHR& info = b.info;
  info = VkAccelerationStructureBuildGeometryInfoKHR{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  info.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
  info.flags = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR;
  info.mode = mode;
  info.srcAccelerationStructure = mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR ? as_.handle : VK_NULL_HANDLE;
  info.dstAccelerationStructure = as_.handle;
  info.geometryCount = 1;
  info.pGeometries = b.geometries.data();
  info.scratchData.deviceAddress = scratch_.address;
  VkAccelerationStructureBuildRangeInfoKHR& range = b.ranges.emplace_back();
  range.primitiveCount = count;
  b.range_pointer = b.ranges.data();
  return b;
}

void Tlas::Record(VkCommandBuffer cb, const vkkit::Buffer& instances, uint32_t count,
                  VkBuildAccelerationStructureModeKHR mode) {
  const BuildInfo b = Info(instances, count, mode);
  procs_.CmdBuild(cb, 1, &b.info, &b.range_pointer);
}

void RecordBuilds(vkkit::Device& device, VkCommandBuffer cb, const std::vector<const BuildInfo*>& infos) {
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> all;
  std::vector<const VkAccelerationStructureBuildRangeInfoKHR*> ranges;
  for (const BuildInfo* b : infos) {
    all.push_back(b->info);
    ranges.push_back(b->range_pointer);
  }
  Procs(device).CmdBuild(cb, static_cast<uint32_t>(all.size()), all.data(), ranges.data());
}

// ---- QueryPool -------------------------------------------------------------------------------------------------

QueryPool::QueryPool(vkkit::Device& device, VkQueryType type, uint32_t count) : device_(device), count_(count) {
  VkQueryPoolCreateInfo info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  info.queryType = type;
  info.queryCount = count;
  vkkit::Check(vkCreateQueryPool(device.handle(), &info, nullptr, &pool_), "vkCreateQueryPool");
}

QueryPool::~QueryPool() { vkDestroyQueryPool(device_.handle(), pool_, nullptr); }

void QueryPool::Reset(VkCommandBuffer cb) { vkCmdResetQueryPool(cb, pool_, 0, count_); }

std::vector<uint64_t> QueryPool::Results(uint32_t first, uint32_t count) {
  if (count == ~0u) count = count_ - first;
  std::vector<uint64_t> results(count);
  const VkQueryResultFlags flags = VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT;
  vkkit::Check(vkGetQueryPoolResults(device_.handle(), pool_, first, count, results.size() * sizeof(uint64_t),
                                     results.data(), sizeof(uint64_t), flags),
               "vkGetQueryPoolResults");
  return results;
}

// ---- copies ----------------------------------------------------------------------------------------------------

void CmdCopy(vkkit::Device& device, VkCommandBuffer cb, VkAccelerationStructureKHR src, VkAccelerationStructureKHR dst,
             VkCopyAccelerationStructureModeKHR mode) {
  VkCopyAccelerationStructureInfoKHR info{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_INFO_KHR};
  info.src = src;
  info.dst = dst;
  info.mode = mode;
  Procs(device).CmdCopy(cb, &info);
}

void CmdSerialize(vkkit::Device& device, VkCommandBuffer cb, VkAccelerationStructureKHR src, VkDeviceAddress dst) {
  VkCopyAccelerationStructureToMemoryInfoKHR info{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_TO_MEMORY_INFO_KHR};
  info.src = src;
  info.dst.deviceAddress = dst;
  info.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_SERIALIZE_KHR;
  Procs(device).CmdCopyToMemory(cb, &info);
}

void CmdDeserialize(vkkit::Device& device, VkCommandBuffer cb, VkDeviceAddress src, VkAccelerationStructureKHR dst) {
  VkCopyMemoryToAccelerationStructureInfoKHR info{VK_STRUCTURE_TYPE_COPY_MEMORY_TO_ACCELERATION_STRUCTURE_INFO_KHR};
  info.src.deviceAddress = src;
  info.dst = dst;
  info.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_DESERIALIZE_KHR;
  Procs(device).CmdCopyMemoryTo(cb, &info);
}

void CmdWriteProperties(vkkit::Device& device, VkCommandBuffer cb, std::vector<VkAccelerationStructureKHR> structures,
                        VkQueryType type, VkQueryPool pool, uint32_t first_query) {
  Procs(device).CmdWriteProperties(cb, static_cast<uint32_t>(structures.size()), structures.data(), type, pool,
                                   first_query);
}

void CmdCopyBuffer(VkCommandBuffer cb, const vkkit::Buffer& src, const vkkit::Buffer& dst, VkDeviceSize size) {
  VkBufferCopy region{0, 0, size};
  vkCmdCopyBuffer(cb, src.buffer, dst.buffer, 1, &region);
}


Shape WithGeometryFlags(VkGeometryFlagsKHR flags) {
  Shape s;
  s.geometry_flags = flags;
  return s;
}

VkCommandBuffer Recorded(Commands& commands, const std::function<void(VkCommandBuffer)>& record) {
  VkCommandBuffer cb = commands.Begin();
  record(cb);
  commands.End(cb);
  return cb;
}

vkkit::DeviceOptions TimelineDevice(uint32_t queues) {
  vkkit::DeviceOptions options;
  options.timeline_semaphore = true;
  options.queue_count = queues;
  return options;
}

Timeline::Timeline(vkkit::Device& device) : device_(device) {
  VkSemaphoreTypeCreateInfo type{VK_STRUCTURE_TYPE_SEMAPHORE_TYPE_CREATE_INFO, nullptr, VK_SEMAPHORE_TYPE_TIMELINE, 0};
  const VkSemaphoreCreateInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO, &type};
  vkkit::Check(vkCreateSemaphore(device.handle(), &info, nullptr, &semaphore_), "vkCreateSemaphore");
}

Timeline::~Timeline() { vkDestroySemaphore(device_.handle(), semaphore_, nullptr); }

VkResult Timeline::HostSignal(uint64_t value) {
  const VkSemaphoreSignalInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_SIGNAL_INFO, nullptr, semaphore_, value};
  return vkSignalSemaphore(device_.handle(), &info);
}

VkResult Timeline::HostWait(uint64_t value, uint64_t timeout_ns) {
  VkSemaphoreWaitInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_WAIT_INFO};
  info.semaphoreCount = 1;
  info.pSemaphores = &semaphore_;
  info.pValues = &value;
  return vkWaitSemaphores(device_.handle(), &info, timeout_ns);
}

VkResult SubmitOn(VkQueue queue, VkCommandBuffer cb, const Timeline& timeline, uint64_t wait, uint64_t signal) {
  const VkSemaphore semaphore = timeline.handle();
  const VkPipelineStageFlags stage = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
  VkTimelineSemaphoreSubmitInfo values{VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO};
  values.waitSemaphoreValueCount = wait ? 1 : 0;
  values.pWaitSemaphoreValues = &wait;
  values.signalSemaphoreValueCount = signal ? 1 : 0;
  values.pSignalSemaphoreValues = &signal;
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO, &values};
  submit.waitSemaphoreCount = wait ? 1 : 0;
  submit.pWaitSemaphores = &semaphore;
  submit.pWaitDstStageMask = &stage;
  submit.signalSemaphoreCount = signal ? 1 : 0;
  submit.pSignalSemaphores = &semaphore;
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cb;
  return vkQueueSubmit(queue, 1, &submit, VK_NULL_HANDLE);
}

}  // namespace asval_test
