#pragma once
// The acceleration-structure operations a command buffer (or one host call) performs, as a compact deep copy
// of what the history rules need: the build parameters an update must repeat, the source and destination of
// copies, where serialized bytes go, which structures a property query reads. Recorded when the command is
// recorded; applied to the structures' histories when the command buffer is submitted (history.h).
//
// A batch owns two flat arrays (operations, and the geometries of every build in it), so recording a build
// appends to vectors that keep their capacity across resets: a steady-state frame allocates nothing.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "memory_range.h"

namespace asval {

class CaptureLog;  // capture_log.h
struct BuildSnapshot;  // history.h

// The command an operation came from (for messages and ordinals).
enum class OpCommand : uint8_t {
  kCmdBuild,
  kCmdBuildIndirect,
  kHostBuild,
  kCmdCopy,
  kHostCopy,
  kCmdCopyToMemory,
  kHostCopyToMemory,
  kCmdCopyMemoryTo,
  kHostCopyMemoryTo,
  kCmdWriteProperties,
  kHostWriteProperties,
  // VK_NV_ray_tracing (issue 30): one structure per command; their operations share the history by handle value.
  kCmdBuildNV,
  kCmdCopyNV,
  kCmdWritePropertiesNV,
  // Trace and ray-query work (OpKind::kTrace): the commands whose bound pipeline reads structure descriptors.
  kCmdTraceRays,
  kCmdTraceRaysIndirect,
  kCmdTraceRaysIndirect2,
  kCmdDispatch,
  kCmdDispatchIndirect,
  kCmdDispatchBase,
  // Draws: ray queries in graphics (and mesh) pipelines.
  kCmdDraw,
  kCmdDrawIndexed,
  kCmdDrawIndirect,
  kCmdDrawIndexedIndirect,
  kCmdDrawIndirectCount,
  kCmdDrawIndexedIndirectCount,
  kCmdDrawMultiEXT,
  kCmdDrawMultiIndexedEXT,
  kCmdDrawIndirectByteCountEXT,
  kCmdDrawMeshTasksEXT,
  kCmdDrawMeshTasksIndirectEXT,
  kCmdDrawMeshTasksIndirectCountEXT,
  kCount
};
constexpr std::size_t kOpCommandCount = static_cast<std::size_t>(OpCommand::kCount);

// "vkCmdBuildAccelerationStructuresKHR", ...
const char* OpCommandName(OpCommand command);
// The array parameter an operation is an element of: "pInfos", "pAccelerationStructures"; "pInfo" for a command of one
// info, "" for one whose operation is its parameters themselves (vkCmdCopyAccelerationStructureNV).
const char* OpCommandArrayName(OpCommand command);
// Whether the command is VK_NV_ray_tracing's: its structures are VkAccelerationStructureNV.
inline bool IsNvCommand(OpCommand command) {
  return command == OpCommand::kCmdBuildNV || command == OpCommand::kCmdCopyNV ||
         command == OpCommand::kCmdWritePropertiesNV;
}

// Where an operation was recorded.
struct OpOrigin {
  OpCommand command = OpCommand::kCmdBuild;
  uint32_t ordinal = 0;     // 1-based: the n-th call of `command` in command_buffer (0 for host calls)
  uint32_t element = 0;     // pInfos[element] / pAccelerationStructures[element]
  VkCommandBuffer command_buffer = VK_NULL_HANDLE;  // where recorded; null for host calls
  VkCommandBuffer executed_by = VK_NULL_HANDLE;     // the primary that ran it, when recorded in a secondary
  // DeviceState::LastObjectId() when recorded (0 for host calls): a structure created or a buffer bound later is
  // not what the command named, one destroyed later leaves the command buffer invalid
  // (layer/checks/recorded_objects.h).
  uint64_t recorded_at = 0;
};

// "pInfos[0] of the 3rd vkCmdBuildAccelerationStructuresKHR in VkCommandBuffer 0x..." (allocates: reports only).
std::string DescribeOrigin(const OpOrigin& origin);

// One geometry of a build, as an update must repeat it (VUIDs 03761..03767, 03769). No member initializers: the
// batch's array grows by `resize` without writing anything (the default constructor is user-provided and empty),
// and the constructor below and Read write every member.
struct GeometryRecord {
  GeometryRecord() {}  // uninitialized: only for arrays whose records Read writes
  // Reads one geometry of a build info; count_known is false for indirect builds.
  GeometryRecord(const VkAccelerationStructureGeometryKHR& geometry, uint32_t count, bool count_known) {
    Read(geometry, count, count_known);
  }
  // Writes every member from one geometry (the triangle members of other types get their defaults).
  void Read(const VkAccelerationStructureGeometryKHR& geometry, uint32_t count, bool count_known);

  VkGeometryTypeKHR type;
  VkGeometryFlagsKHR flags;
  VkFormat vertex_format;       // triangles only (else VK_FORMAT_UNDEFINED)
  VkIndexType index_type;       // triangles only (else VK_INDEX_TYPE_NONE_KHR)
  uint32_t max_vertex;          // triangles only (else 0)
  uint32_t primitive_count;
  bool has_transform;           // triangles: transformData non-null (else false)
  bool primitive_count_known;   // false for indirect builds (the count is on the device)

  friend bool operator==(const GeometryRecord& a, const GeometryRecord& b) {
    return a.type == b.type && a.flags == b.flags && a.vertex_format == b.vertex_format &&
           a.index_type == b.index_type && a.max_vertex == b.max_vertex && a.primitive_count == b.primitive_count &&
           a.has_transform == b.has_transform && a.primitive_count_known == b.primitive_count_known;
  }
  friend bool operator!=(const GeometryRecord& a, const GeometryRecord& b) { return !(a == b); }
};
static_assert(std::is_trivially_copyable_v<GeometryRecord>, "copied as bytes");

enum class OpKind : uint8_t {
  kBuild,            // a build or update (mode says which) of dst
  kCopy,             // clone or compact src into dst
  kSerialize,        // src into memory
  kDeserialize,      // memory into dst
  kWriteProperties,  // a property query of dst
  kTrace,            // a trace or dispatch reading the structures of its bound descriptors (OpBatch::traced)
};

// Where serialized bytes live: device memory (resolved through the address map when recorded) or host memory.
struct SerializedLocation {
  VkDeviceAddress device_address = 0;
  const void* host_address = nullptr;
  // The VkDeviceMemory bytes behind device_address, as far as the buffer containing it reaches; memory is
  // VK_NULL_HANDLE when the address is in no buffer the layer knows (or the memory is not known).
  MemorySpan span;
  // Bytes from the address to the end of the largest buffer containing it; 0 when unknown.
  VkDeviceSize capacity = 0;
};

struct AsOp {
  // User-provided, so that value-initialization (emplace_back()) runs the member initializers only, without
  // zeroing the whole operation first.
  AsOp() {}
  // A build or update of pInfos[element] of a build command recorded at `at`, whose geometries start at
  // first_geometry in its batch: the build members written once, the others their defaults.
  AsOp(const OpOrigin& at, uint32_t element, const VkAccelerationStructureBuildGeometryInfoKHR& info,
       uint32_t first_geometry_index)
      : mode(info.mode),
        origin(at),
        src(info.mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR ? info.srcAccelerationStructure
                                                                         : VK_NULL_HANDLE),
        dst(info.dstAccelerationStructure),
        flags(info.flags),
        type(info.type),
        geometry_count(info.geometryCount),
        first_geometry(first_geometry_index) {
    origin.element = element;
  }

  // The members are ordered by size within the groups below, so that the operation has no padding but the
  // origin's (160 bytes: the batch's array grows and the command buffers copy them).
  OpKind kind = OpKind::kBuild;
  // kBuild: the geometries could not be read (a null ppGeometries[j], or neither array given with
  // geometryCount > 0): an invalid build, reported by the structure family; what it leaves in dst is unknown.
  bool geometries_unreadable = false;
  VkBuildAccelerationStructureModeKHR mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;  // kBuild
  OpOrigin origin;
  VkAccelerationStructureKHR src = VK_NULL_HANDLE;  // build (updates), copy, serialize
  VkAccelerationStructureKHR dst = VK_NULL_HANDLE;  // build, copy, deserialize, write properties

  // kBuild
  VkBuildAccelerationStructureFlagsKHR flags = 0;
  VkAccelerationStructureTypeKHR type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  uint32_t geometry_count = 0;   // kTrace: how many of the batch's traced bindings are its own
  uint32_t first_geometry = 0;  // index into the batch's geometries; kTrace: into its traced bindings
  // The bytes this build read, captured when it executes (issue 12): capture_info is its index in
  // capture_log->infos; capture_log is null when the build was not captured. The log is kept alive by the
  // published recording that holds this operation (RecordedOps::capture_logs). kSerialize / kDeserialize of
  // device memory: the serialized bytes written / read, capture_info indexing capture_log->blobs.
  CaptureLog* capture_log = nullptr;
  uint32_t capture_info = 0;

  // kCopy, kSerialize, kDeserialize
  VkCopyAccelerationStructureModeKHR copy_mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR;
  SerializedLocation memory;  // kSerialize: destination; kDeserialize: source

  // kWriteProperties
  VkQueryType query_type = VK_QUERY_TYPE_OCCLUSION;
  uint32_t query = 0;                       // firstQuery + element
  VkQueryPool query_pool = VK_NULL_HANDLE;  // null for host writes

  bool is_update() const { return kind == OpKind::kBuild && mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR; }
  // An indirect build whose range infos the layer captures: its primitive counts are read when it executes, and
  // an update's comparison of them (primitiveCount-03769) is judged, or counted as skipped, when its submission
  // completes (layer/checks/indirect_rules.h), not at submission.
  bool counts_captured() const { return origin.command == OpCommand::kCmdBuildIndirect && capture_log != nullptr; }
};
static_assert(sizeof(AsOp) == 160, "no padding but the origin's: see the member order");

// A device address an operation reads or writes (issue 29: what a pending submission holds in use). The first
// byte of each range is enough to name the buffer and memory behind it (a range of a valid command lies in one
// buffer). Device commands only: host commands complete within their call.
enum class TouchRole : uint8_t { kScratch, kVertices, kIndices, kTransform, kAabbs, kInstances, kSerialized };
// "scratchData", "vertexData", ... (the field that holds the address).
const char* TouchRoleName(TouchRole role);
// Trivial: the batch's array grows by `resize` (a memset) and is written in place.
struct AddressTouch {
  VkDeviceAddress address;
  uint32_t op;  // index of the operation in its batch
  TouchRole role;
};
static_assert(std::is_trivial_v<AddressTouch>, "grown by a memset, written in place");

// A structure binding that a trace or dispatch reads (issue 29, family traces): which descriptor the pipeline bound
// then names there. Sets are looked up when the command is submitted (a set updated after binding, as
// UPDATE_AFTER_BIND allows, is read as it is then); pushed descriptors are copied when pushed.
enum class TracedSource : uint8_t {
  kSet,         // `set`, bound at set number set_index
  kPushed,      // `pushed` (with its serial), pushed with vkCmdPushDescriptorSetKHR
  kNotBound,    // nothing bound at that set number (or that binding was not pushed)
  kBuffer,      // read from descriptor bytes at descriptor_address (VK_EXT_descriptor_buffer), at submission
  kUnknown,     // pushed with a template, or a descriptor-buffer layout the layer could not lay out: not followed
};
// The instruction that reads the binding, for the rule's VUID.
enum class TracedBy : uint8_t { kTraceRay, kRayQuery };
struct TracedBinding {
  uint32_t set_index;
  uint32_t binding;
  TracedSource source;
  TracedBy by;
  uint32_t descriptor_count;  // kBuffer: the binding's descriptorCount
  VkDescriptorSet set;
  VkAccelerationStructureKHR pushed;
  uint64_t pushed_serial;  // AccelerationStructureState::serial when pushed (0: unknown)
  VkDeviceAddress descriptor_address;  // kBuffer: the binding's first descriptor in the bound descriptor buffer
};
static_assert(std::is_trivial_v<TracedBinding>, "copied as bytes");

// A growable array of trivial records that grows without writing them (std::vector value-initializes what it
// adds), for arrays written in place by the caller. Keeps its capacity across Clear.
template <typename T>
class TrivialArray {
  static_assert(std::is_trivial_v<T>, "grown without construction, copied as bytes");

 public:
  TrivialArray() = default;
  TrivialArray(const TrivialArray& other) { *this = other; }
  TrivialArray& operator=(const TrivialArray& other) {
    if (this != &other) {
      clear();
      if (other.size_ != 0) std::memcpy(Extend(other.size_), other.data_.get(), other.size_ * sizeof(T));
    }
    return *this;
  }

  const T* begin() const { return data_.get(); }
  const T* end() const { return data_.get() + size_; }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  void clear() { size_ = 0; }
  // Room for `extra` more records past size(), not written: returns where they start. Throws std::bad_alloc.
  T* Extend(std::size_t extra) {
    if (size_ + extra > capacity_) Grow(size_ + extra);
    T* at = data_.get() + size_;
    size_ += extra;
    return at;
  }
  // Keeps the first `size` records.
  void Truncate(std::size_t size) { size_ = size < size_ ? size : size_; }
  void push_back(const T& value) { *Extend(1) = value; }
  void swap(TrivialArray& other) noexcept {
    data_.swap(other.data_);
    std::swap(size_, other.size_);
    std::swap(capacity_, other.capacity_);
  }

 private:
  void Grow(std::size_t needed) {
    const std::size_t capacity = needed > 2 * capacity_ ? needed : 2 * capacity_;
    std::unique_ptr<T[]> data(new T[capacity]);  // default-initialized: not written
    if (size_ != 0) std::memcpy(data.get(), data_.get(), size_ * sizeof(T));
    data_ = std::move(data);
    capacity_ = capacity;
  }

  std::unique_ptr<T[]> data_;
  std::size_t size_ = 0;
  std::size_t capacity_ = 0;
};

// A sequence of operations in execution order, with their geometries.
class OpBatch {
 public:
  const std::vector<AsOp>& ops() const { return ops_; }
  const std::vector<GeometryRecord>& geometries() const { return geometries_; }
  // The device addresses the operations read or write (scratch, geometry inputs, serialized bytes).
  const TrivialArray<AddressTouch>& touches() const { return touches_; }
  // The structure bindings of the kTrace operations (each names its own by first_geometry / geometry_count).
  const TrivialArray<TracedBinding>& traced() const { return traced_; }
  const GeometryRecord* GeometriesOf(const AsOp& op) const { return geometries_.data() + op.first_geometry; }
  bool empty() const { return ops_.empty(); }
  // The operations could not all be recorded (an allocation failed: host commands, history_recorder.cpp): what
  // the command does to structures is unknown. Set without allocating.
  bool lost() const { return lost_; }
  void MarkLost() { lost_ = true; }

  // Clears and keeps the capacity.
  void Clear();
  void Swap(OpBatch& other) noexcept {
    ops_.swap(other.ops_);
    geometries_.swap(other.geometries_);
    touches_.swap(other.touches_);
    traced_.swap(other.traced_);
    applied_snapshots_.swap(other.applied_snapshots_);
    std::swap(lost_, other.lost_);
  }

  // A submitted batch remembers, per operation, the parameter snapshot it left in its destination when it was
  // last applied (history_apply.cpp): applied again, a build that finds that snapshot still there shares it on a
  // pointer comparison instead of comparing its parameters again. Sized when a recording is published; written
  // only with the history store's lock held (the published batch is otherwise immutable, and every submission
  // applies under that lock). Null for other batches (host operations, tests): they compare.
  void RememberSnapshots() { applied_snapshots_.assign(ops_.size(), nullptr); }
  std::shared_ptr<const BuildSnapshot>* AppliedSnapshot(const AsOp& op) const {
    const std::size_t i = static_cast<std::size_t>(&op - ops_.data());
    return i < applied_snapshots_.size() ? &applied_snapshots_[i] : nullptr;
  }

  // One operation per info of a build command. ranges is null for indirect builds (counts unknown).
  // captured: per info, its index in `log`'s infos plus one (0: not captured); null when nothing was.
  // max_geometry_count: the device's limit (0: not reported); past it an info's geometries are not read (its arrays
  // may be shorter than its count, type-03793) and its operation's geometries are unreadable.
  // touches: a device build's addresses are kept (touches()); false where nothing reads them (family lifetime off).
  void AppendBuilds(const OpOrigin& origin, uint32_t info_count,
                    const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                    const VkAccelerationStructureBuildRangeInfoKHR* const* ranges,
                    CaptureLog* log = nullptr, const uint32_t* captured = nullptr, uint64_t max_geometry_count = 0,
                    bool touches = true);
  // A trace or dispatch reading `count` structure bindings (kTrace).
  void AppendTrace(const OpOrigin& origin, const TracedBinding* bindings, uint32_t count);
  // vkCmdBuildAccelerationStructureNV: one build or update of dst (keys: NvHistoryKey), its geometries recorded as a
  // KHR build's would be (a top level as one instance geometry of instanceCount). Beyond max_geometry_count (its
  // limit; 0: unknown, no limit) the geometries are not walked: the build is invalid as a whole (geometryCount-02241).
  void AppendNvBuild(const OpOrigin& origin, const VkAccelerationStructureInfoNV& info, bool update,
                     VkAccelerationStructureKHR dst, VkAccelerationStructureKHR src, uint64_t max_geometry_count);
  // Any other operation (no geometries); device serialization and deserialization touch their bytes.
  void Append(const AsOp& op);
  // Appends every operation of another batch (a secondary command buffer), marking it as run by `primary`.
  void AppendExecuted(const OpBatch& secondary, VkCommandBuffer primary);
  // The operations appended so far that read their captures from `from` read them from `to` instead (the
  // earlier executions of a secondary executed again: layer/capture/capture_saves.h).
  void MoveCaptures(const CaptureLog* from, CaptureLog* to) {
    for (AsOp& op : ops_) {
      if (op.capture_log == from) op.capture_log = to;
    }
  }

 private:
  // The geometries of one info from pGeometries, appended at once (capacity reserved by the caller).
  void AppendInPlace(const VkAccelerationStructureBuildGeometryInfoKHR& info,
                     const VkAccelerationStructureBuildRangeInfoKHR* info_ranges);

  std::vector<AsOp> ops_;
  // The geometry inputs and scratch of one device build (operation index op), appended to touches_.
  void AppendTouches(uint32_t op, const VkAccelerationStructureBuildGeometryInfoKHR& info);

  std::vector<GeometryRecord> geometries_;
  TrivialArray<AddressTouch> touches_;
  TrivialArray<TracedBinding> traced_;
  mutable std::vector<std::shared_ptr<const BuildSnapshot>> applied_snapshots_;
  bool lost_ = false;
};


}  // namespace asval
