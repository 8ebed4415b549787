#pragma once
// Helpers for the build-history and copies tests: command buffers recorded now and submitted later (in any
// order, more than once), bottom- and top-level structures whose builds and updates take a "shape" (the
// parameters an update must repeat), copies, serialization and property queries.
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "fixture.h"

namespace asval_test {

// A Fixture whose enabled_checks names only `families` (null: every family), plus any other settings.
// Negative tests narrow the families, so that a rule of another family about the same deliberately broken
// input adds no finding of its own; valid twins keep every family on.
class HistoryFixture {
 public:
  explicit HistoryFixture(const char* families = nullptr,
                          const std::vector<std::pair<const char*, const char*>>& settings = {},
                          const vkkit::DeviceOptions& device = {});
  Monitor& monitor() { return fixture_->monitor(); }
  vkkit::Instance& instance() { return fixture_->instance(); }
  vkkit::Device& device() { return fixture_->device(); }
  // Destroys the device and the instance now, e.g. for the summary vkDestroyDevice writes to a report file.
  void Close() { fixture_.reset(); }

 private:
  ApiSettings settings_;
  std::unique_ptr<Fixture> fixture_;
};

// Entry points the tests call that vkkit does not load.
struct Procs {
  explicit Procs(vkkit::Device& device);
  PFN_vkCmdBuildAccelerationStructuresKHR CmdBuild = nullptr;
  PFN_vkBuildAccelerationStructuresKHR HostBuild = nullptr;
  PFN_vkCmdCopyAccelerationStructureKHR CmdCopy = nullptr;
  PFN_vkCmdCopyAccelerationStructureToMemoryKHR CmdCopyToMemory = nullptr;
  PFN_vkCmdCopyMemoryToAccelerationStructureKHR CmdCopyMemoryTo = nullptr;
  PFN_vkCmdWriteAccelerationStructuresPropertiesKHR CmdWriteProperties = nullptr;
  PFN_vkCopyAccelerationStructureKHR HostCopy = nullptr;
  PFN_vkWriteAccelerationStructuresPropertiesKHR HostWriteProperties = nullptr;
  PFN_vkCmdExecuteCommands CmdExecuteCommands = nullptr;
  PFN_vkQueueSubmit2 QueueSubmit2 = nullptr;
  // One vkQueueSubmit2 of `cb` alone, no fence, not waited for (QueueSubmit2 must be loaded).
  VkResult Submit2(VkQueue queue, VkCommandBuffer cb) const;
};

// Command buffers from one pool, recorded whenever and submitted in any order; all freed at the end.
class Commands {
 public:
  explicit Commands(vkkit::Device& device);
  ~Commands();
  VkCommandBuffer Begin();           // a new primary command buffer, begun
  // A new secondary command buffer, begun (no render pass) with `flags` (e.g. SIMULTANEOUS_USE, to execute it
  // twice in one primary).
  VkCommandBuffer BeginSecondary(VkCommandBufferUsageFlags flags = 0);
  void End(VkCommandBuffer cb);
  // AS-build and AS-copy writes before the next AS-build/copy reads and writes (and query writes).
  void Barrier(VkCommandBuffer cb);
  // Submits `cbs` as one batch and, when the layer let it through, waits for the queue. The layer's result.
  VkResult Submit(const std::vector<VkCommandBuffer>& cbs);
  VkResult Submit(VkCommandBuffer cb) { return Submit(std::vector<VkCommandBuffer>{cb}); }
  VkCommandPool pool() const { return pool_; }

 private:
  vkkit::Device& device_;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  std::vector<VkCommandBuffer> buffers_;
};

// The parameters of a bottom-level build that an update must repeat.
struct Shape {
  uint32_t geometries = 1;
  uint32_t triangles = 1;  // primitiveCount of each geometry
  VkBuildAccelerationStructureFlagsKHR flags =
      VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR | VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
  VkAccelerationStructureTypeKHR type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  VkGeometryTypeKHR geometry_type = VK_GEOMETRY_TYPE_TRIANGLES_KHR;  // or VK_GEOMETRY_TYPE_AABBS_KHR
  VkGeometryFlagsKHR geometry_flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
  VkFormat vertex_format = VK_FORMAT_R32G32B32_SFLOAT;
  VkDeviceSize vertex_stride = 12;  // Inputs' own vertices are R32G32B32_SFLOAT, tightly packed
  uint32_t max_vertex = 0;  // 0: the highest vertex the triangles use
  VkIndexType index_type = VK_INDEX_TYPE_NONE_KHR;
  bool transform = false;
  // Each geometry's build range (VkAccelerationStructureBuildRangeInfoKHR), besides primitiveCount.
  uint32_t primitive_offset = 0;
  uint32_t first_vertex = 0;
};

// Build inputs for any Shape (up to kMaxGeometries geometries of kMaxTriangles triangles): vertices, 32-bit
// indices, a transform and AABBs, in one host-visible buffer. `extra_usage` is added to the buffer's usage
// (TRANSFER_DST for tests that write the inputs on the device).
class Inputs {
 public:
  static constexpr uint32_t kMaxGeometries = 3;
  static constexpr uint32_t kMaxTriangles = 2;
  static constexpr uint32_t kVertexCount = 16;
  // Byte offsets of each input in buffer().
  static constexpr VkDeviceSize kVerticesOffset = 0;
  static constexpr VkDeviceSize kIndicesOffset = 256;
  static constexpr VkDeviceSize kTransformOffset = 512;
  static constexpr VkDeviceSize kAabbsOffset = 768;
  explicit Inputs(vkkit::Device& device, VkBufferUsageFlags extra_usage = 0);
  ~Inputs();
  Inputs(const Inputs&) = delete;
  Inputs& operator=(const Inputs&) = delete;
  VkDeviceAddress vertices() const { return buffer_.address + kVerticesOffset; }
  VkDeviceAddress indices() const { return buffer_.address + kIndicesOffset; }
  VkDeviceAddress transform() const { return buffer_.address + kTransformOffset; }
  VkDeviceAddress aabbs() const { return buffer_.address + kAabbsOffset; }
  const vkkit::Buffer& buffer() const { return buffer_; }
  // The test destroyed the buffer or freed the memory itself (lifetime tests): the destructor leaves them alone.
  void Forget() { buffer_ = vkkit::Buffer{}; }

 private:
  vkkit::Device& device_;
  vkkit::Buffer buffer_;
};

// What a vkCmdBuild/vkBuild call needs for one info of a Shape, kept alive while the call runs.
struct BuildInfo {
  std::vector<VkAccelerationStructureGeometryKHR> geometries;
  std::vector<VkAccelerationStructureBuildRangeInfoKHR> ranges;
  VkAccelerationStructureBuildGeometryInfoKHR info{};
  const VkAccelerationStructureBuildRangeInfoKHR* range_pointer = nullptr;
};
BuildInfo MakeBuildInfo(const Shape& shape, const Inputs& inputs);

// A structure with storage and scratch big enough for any Shape. `shared` places it in another structure's
// storage buffer (at `offset`, a multiple of 256: with 0 the two alias at the same address) instead of a buffer of
// its own.
class Blas {
 public:
  Blas(vkkit::Device& device, const Inputs& inputs, const Blas* shared = nullptr, VkDeviceSize offset = 0);
  ~Blas();
  Blas(const Blas&) = delete;
  Blas& operator=(const Blas&) = delete;

  VkAccelerationStructureKHR handle() const { return handle_; }
  VkDeviceAddress address() const { return address_; }
  void SetInputs(const Inputs& inputs) { inputs_ = &inputs; }

  void Build(VkCommandBuffer cb, const Shape& shape);
  // An update of `src` (this structure itself when null) into this structure.
  void Update(VkCommandBuffer cb, const Shape& shape, const Blas* src = nullptr);
  // vkBuildAccelerationStructuresKHR (host): an update of this structure in place. Only for calls the layer
  // skips (lavapipe has no host commands).
  VkResult HostUpdate(const Shape& shape);
  // Destroys the structure (not its storage) and creates a new one in the same place.
  void Recreate();
  // Destroys the structure, not its storage: address() stays backed by the same memory (a driver that reads the
  // structures a top-level build's instances reference finds bytes there) but names no live structure.
  void DestroyHandle();
  // Destroys the VkBuffer the structure was created on (its own storage), not its memory nor the structure: the
  // handle stays alive on a buffer that is gone, address() stays backed by the same memory.
  void DestroyStorageBuffer();
  // Frees the memory the structure's own storage buffer is bound to; the structure and the buffer stay alive.
  void FreeStorageMemory();
  // Deferred deletion, as engines do it: destroys the VkBuffer the structure was created on while its handle is
  // kept (returned: the caller destroys it later), binds a new buffer to the same memory at the same offset and
  // creates a new, unbuilt structure there, which gets the old one's address (on lavapipe a buffer's address is its
  // memory's plus the offset: the caller checks). Only for a structure with storage of its own.
  VkAccelerationStructureKHR Relocate();
  // The info Build/Update would record (dst, src and scratch set), for a call of several infos (RecordBuilds).
  BuildInfo Info(const Shape& shape, VkBuildAccelerationStructureModeKHR mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR) const;

 private:
  void Create();
  void Record(VkCommandBuffer cb, const Shape& shape, VkBuildAccelerationStructureModeKHR mode,
              VkAccelerationStructureKHR src);

  vkkit::Device& device_;
  Procs procs_;
  const Inputs* inputs_;
  vkkit::Buffer storage_;  // own storage (empty when shared)
  VkBuffer storage_buffer_ = VK_NULL_HANDLE;
  VkDeviceSize size_ = 0;
  VkDeviceSize offset_ = 0;  // in the storage buffer
  vkkit::Buffer scratch_;
  VkAccelerationStructureKHR handle_ = VK_NULL_HANDLE;
  VkDeviceAddress address_ = 0;
};

// An instance of `reference` (0: inactive), an identity transform moved 4 units along X per index `i`, mask 0xff.
VkAccelerationStructureInstanceKHR InstanceRecord(VkDeviceAddress reference, uint32_t i);

// A top-level structure over up to `max_instances` instances of bottom-level structures, read from an instance
// buffer that the caller may replace every frame.
class Tlas {
 public:
  explicit Tlas(vkkit::Device& device, uint32_t max_instances = 4);
  ~Tlas();
  // A new instance buffer referencing `blases` (one instance each).
  vkkit::Buffer MakeInstances(const std::vector<const Blas*>& blases);
  void Record(VkCommandBuffer cb, const vkkit::Buffer& instances, uint32_t count,
              VkBuildAccelerationStructureModeKHR mode);
  // The info Record would record, for a call of several infos (RecordBuilds).
  BuildInfo Info(const vkkit::Buffer& instances, uint32_t count, VkBuildAccelerationStructureModeKHR mode) const;
  VkAccelerationStructureKHR handle() const { return as_.handle; }
  // The structure's device address (vkGetAccelerationStructureDeviceAddressKHR).
  VkDeviceAddress address() const;
  // Destroys the structure, not its storage (lifetime tests).
  void DestroyHandle();
  // Destroys the VkBuffer of its storage, not the structure nor the memory; or frees the memory, not the buffer
  // (lifetime tests: what a pending trace of it reads).
  void DestroyStorageBuffer();
  void FreeStorageMemory();

 private:
  vkkit::Device& device_;
  Procs procs_;
  vkkit::AccelerationStructure as_;
  vkkit::Buffer scratch_;
};

// One vkCmdBuildAccelerationStructuresKHR of all these infos, in this order.
void RecordBuilds(vkkit::Device& device, VkCommandBuffer cb, const std::vector<const BuildInfo*>& infos);

// A query pool of `count` queries of `type`, reset by vkCmdResetQueryPool in Reset().
class QueryPool {
 public:
  QueryPool(vkkit::Device& device, VkQueryType type, uint32_t count);
  ~QueryPool();
  VkQueryPool handle() const { return pool_; }
  void Reset(VkCommandBuffer cb);
  // Waits for and returns the 64-bit results.
  // Waits for queries [first, first + count) (all by default). Ask only for queries the test wrote: waiting
  // on one that is never written may block forever on a real driver.
  std::vector<uint64_t> Results(uint32_t first = 0, uint32_t count = ~0u);

 private:
  vkkit::Device& device_;
  VkQueryPool pool_ = VK_NULL_HANDLE;
  uint32_t count_ = 0;
};

// Copy commands.
void CmdCopy(vkkit::Device& device, VkCommandBuffer cb, VkAccelerationStructureKHR src, VkAccelerationStructureKHR dst,
             VkCopyAccelerationStructureModeKHR mode);
void CmdSerialize(vkkit::Device& device, VkCommandBuffer cb, VkAccelerationStructureKHR src, VkDeviceAddress dst);
void CmdDeserialize(vkkit::Device& device, VkCommandBuffer cb, VkDeviceAddress src, VkAccelerationStructureKHR dst);
void CmdWriteProperties(vkkit::Device& device, VkCommandBuffer cb, std::vector<VkAccelerationStructureKHR> structures,
                        VkQueryType type, VkQueryPool pool, uint32_t first_query);
// vkCmdCopyBuffer of `size` bytes (a write the layer does not track).
void CmdCopyBuffer(VkCommandBuffer cb, const vkkit::Buffer& src, const vkkit::Buffer& dst, VkDeviceSize size);


// Shapes that differ only in their geometry flags: among what an update must repeat (03762), and a mismatch is
// harmless to a driver that executes it (tests whose invalid update goes down use them).
Shape WithGeometryFlags(VkGeometryFlagsKHR flags);
inline const Shape kOpaque = WithGeometryFlags(VK_GEOMETRY_OPAQUE_BIT_KHR);
inline const Shape kNoDuplicate = WithGeometryFlags(VK_GEOMETRY_NO_DUPLICATE_ANY_HIT_INVOCATION_BIT_KHR);

// A new primary command buffer of `commands` with what `record` records, ended.
VkCommandBuffer Recorded(Commands& commands, const std::function<void(VkCommandBuffer)>& record);

// A device with timeline semaphores and `queues` queues of its family (as many as it offers: Device::queue_count()).
vkkit::DeviceOptions TimelineDevice(uint32_t queues = 1);

// A timeline semaphore (initial value 0).
class Timeline {
 public:
  explicit Timeline(vkkit::Device& device);
  ~Timeline();
  Timeline(const Timeline&) = delete;
  Timeline& operator=(const Timeline&) = delete;
  VkSemaphore handle() const { return semaphore_; }
  VkResult HostSignal(uint64_t value);
  // vkWaitSemaphores for `value`, at most `timeout_ns`.
  VkResult HostWait(uint64_t value, uint64_t timeout_ns);

 private:
  vkkit::Device& device_;
  VkSemaphore semaphore_ = VK_NULL_HANDLE;
};

// Submits cb on `queue`, waiting for timeline >= wait (0: no wait) and signaling `signal` (0: none); no fence.
VkResult SubmitOn(VkQueue queue, VkCommandBuffer cb, const Timeline& timeline, uint64_t wait, uint64_t signal);

}  // namespace asval_test
