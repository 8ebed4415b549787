// Fuzz target: the build history (layer/state/history*, history_apply, submission) over random sequences of
// structure creations and destructions (handle values reused), recordings into command buffers (builds, updates,
// indirect builds, copies, device and host serialization, property writes, secondaries), submissions of command
// buffers in any order (accepted, or rejected and undone, with host operations completing in between), host
// operations (at once or deferred), size read-backs and query results. After every step what the store holds is
// compared with the reference model (history_model.h); any difference aborts with the step and the fact that
// differs. The history rules (CheckOpHistory) run before each submitted operation, as in vkQueueSubmit, for
// sanitizer coverage of the rules on every state the sequence reaches.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "history_apply.h"
#include "history_model.h"
#include "history_recorder.h"
#include "layer_settings.h"
#include "state_tracker.h"
#include "submission.h"
#include "update_rules.h"
#include "vk_dispatch_table.h"

namespace asval::fuzz {
namespace {

template <typename H>
H Fake(uintptr_t v) {
  return reinterpret_cast<H>(v);
}

VKAPI_ATTR VkDeviceAddress VKAPI_CALL FakeBufferAddress(VkDevice, const VkBufferDeviceAddressInfo* info) {
  return reinterpret_cast<uintptr_t>(info->buffer) * 0x100000;
}
VKAPI_ATTR VkDeviceAddress VKAPI_CALL FakeAsAddress(VkDevice, const VkAccelerationStructureDeviceAddressInfoKHR* info) {
  return reinterpret_cast<uintptr_t>(info->accelerationStructure) * 0x100;
}

constexpr VkDeviceSize kGrid = 16 << 10;          // structures and serialized data start on 16 KiB steps
constexpr uint32_t kGridSteps = 16;
constexpr VkDeviceSize kMemorySize = 1 << 24;
constexpr uintptr_t kDataBuffer = 0x1000;         // one buffer over the whole memory: serialized data
constexpr uint32_t kPrimaries = 4;
constexpr uint32_t kCommandBuffers = kPrimaries + 1;  // the last is a secondary
constexpr uint32_t kQueries = 8;
constexpr uint32_t kDeferred = 2;
constexpr uint32_t kAllChecks = kCheckHistory | kCheckCopies;
const VkDeviceMemory kMemory = Fake<VkDeviceMemory>(1);
const VkQueryPool kPool = Fake<VkQueryPool>(0x500);
const VkCommandPool kCommandPool = Fake<VkCommandPool>(0x600);

VkAccelerationStructureKHR Handle(uint32_t i) { return Fake<VkAccelerationStructureKHR>(0x10 + i); }
VkCommandBuffer CommandBuffer(uint32_t i) { return Fake<VkCommandBuffer>(0x700 + i); }

struct Reader {
  const uint8_t* p;
  size_t n;
  bool empty() const { return n == 0; }
  uint8_t Byte() { return n ? (--n, *p++) : 0; }
  uint32_t Below(uint32_t bound) { return Byte() % bound; }
  bool Bit() { return Byte() & 1; }
};

[[noreturn]] void Mismatch(int step, const std::string& what) {
  std::fprintf(stderr, "asval_fuzz_history: step %d: the history differs from the reference model: %s\n", step,
               what.c_str());
  std::abort();
}

// A build info with its geometries and ranges, generated from the input, and its parameters for the model.
struct GeneratedBuild {
  std::vector<VkAccelerationStructureGeometryKHR> geometries;
  std::vector<const VkAccelerationStructureGeometryKHR*> pointers;
  std::vector<VkAccelerationStructureBuildRangeInfoKHR> ranges;
  VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  const VkAccelerationStructureBuildRangeInfoKHR* range_pointer = nullptr;
  ModelOp op;
};

void Generate(Reader& r, bool may_be_indirect, GeneratedBuild* b) {
  ModelOp& op = b->op;
  op.kind = ModelOp::kBuild;
  op.dst = r.Below(kHandles);
  op.update = r.Bit();
  op.src = r.Bit() ? op.dst : r.Below(kHandles);
  op.indirect = may_be_indirect && r.Below(4) == 0;
  const uint8_t shape = r.Byte();
  const VkBuildAccelerationStructureFlagsKHR flag_choices[] = {
      VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR, VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR,
      VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR};
  op.params.flags = 0;
  for (int i = 0; i < 3; ++i) {
    if (shape & (1 << i)) op.params.flags |= flag_choices[i];
  }
  op.params.type = (shape & 8) ? VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR
                               : VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  // Mostly 1..2 geometries, so that updates repeat their sources often; now and then 8..9 (the in-place path).
  const uint32_t count = (shape & 0x70) == 0x70 ? 8 + r.Below(2) : (shape >> 4) % 3;
  const bool by_pointers = shape & 0x80;
  for (uint32_t j = 0; j < count; ++j) {
    const uint8_t g = r.Byte();
    VkAccelerationStructureGeometryKHR geometry{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    ModelGeometry m;
    const VkGeometryTypeKHR types[] = {VK_GEOMETRY_TYPE_TRIANGLES_KHR, VK_GEOMETRY_TYPE_TRIANGLES_KHR,
                                       VK_GEOMETRY_TYPE_AABBS_KHR, VK_GEOMETRY_TYPE_INSTANCES_KHR};
    geometry.geometryType = m.type = types[g & 3];
    geometry.flags = m.flags = (g & 4) ? VK_GEOMETRY_OPAQUE_BIT_KHR : 0;
    if (m.type == VK_GEOMETRY_TYPE_TRIANGLES_KHR) {
      auto& t = geometry.geometry.triangles;
      t.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
      t.vertexFormat = m.vertex_format = (g & 8) ? VK_FORMAT_R16G16B16A16_SFLOAT : VK_FORMAT_R32G32B32_SFLOAT;
      const VkIndexType index_types[] = {VK_INDEX_TYPE_NONE_KHR, VK_INDEX_TYPE_UINT16, VK_INDEX_TYPE_UINT32,
                                         VK_INDEX_TYPE_UINT32};
      t.indexType = m.index_type = index_types[(g >> 4) & 3];
      t.maxVertex = m.max_vertex = (g & 0x40) ? 8 : 3;
      m.has_transform = (g & 0x80) != 0;
      t.transformData.deviceAddress = m.has_transform ? 0x40000 : 0;
    } else if (m.type == VK_GEOMETRY_TYPE_AABBS_KHR) {
      geometry.geometry.aabbs.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_AABBS_DATA_KHR;
      geometry.geometry.aabbs.stride = 24;
    } else {
      geometry.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
    }
    m.count_known = !op.indirect;
    m.primitive_count = op.indirect ? 0 : (g >> 5) % 3;
    b->geometries.push_back(geometry);
    b->ranges.push_back(VkAccelerationStructureBuildRangeInfoKHR{m.primitive_count, 0, 0, 0});
    op.params.geometries.push_back(m);
  }
  // Rarely, an invalid build whose geometries cannot be read (a null ppGeometries element, or no array).
  const uint8_t broken = count ? r.Below(16) : 16;
  for (auto& g : b->geometries) b->pointers.push_back(&g);
  if (broken == 0) b->pointers[r.Below(count)] = nullptr;
  op.unreadable = broken <= 1;
  op.params.geometries.resize(op.unreadable ? 0 : count);

  VkAccelerationStructureBuildGeometryInfoKHR& info = b->info;
  info.type = op.params.type;
  info.flags = op.params.flags;
  info.mode = op.update ? VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR : VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  info.srcAccelerationStructure = Handle(op.src);
  info.dstAccelerationStructure = Handle(op.dst);
  info.geometryCount = count;
  if (broken == 1) {
    // geometryCount without either array
  } else if (by_pointers || broken == 0) {
    info.ppGeometries = b->pointers.data();
  } else {
    info.pGeometries = b->geometries.data();
  }
  b->range_pointer = b->ranges.data();
}

struct CommandBufferModel {
  bool allocated = true;
  bool recording = false;
  bool lost = false;            // recording: it executed a secondary the layer does not know
  std::vector<ModelOp> ops;     // recording
  bool published = false;       // a completed recording with operations (or lost)
  bool published_lost = false;
  std::vector<ModelOp> published_ops;
};

class Harness {
 public:
  Harness() {
    state_.features.acceleration_structure = true;
    state_.features.acceleration_structure_host_commands = true;
    state_.features.acceleration_structure_indirect_build = true;
    dispatch_.GetBufferDeviceAddress = &FakeBufferAddress;
    dispatch_.GetAccelerationStructureDeviceAddressKHR = &FakeAsAddress;
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, nullptr, kMemorySize, 0};
    RecordAllocateMemory(state_, alloc, kMemory);
    Buffer(Fake<VkBuffer>(kDataBuffer), kMemorySize, 0);
    VkQueryPoolCreateInfo pool{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    pool.queryType = VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR;
    pool.queryCount = kQueries;
    RecordCreateQueryPool(state_, pool, kPool);
    state_.command_buffers.CreatePool(kCommandPool, 0);
    for (uint32_t i = 0; i < kCommandBuffers; ++i) Allocate(i);
    for (auto& bytes : host_) {
      bytes.assign(kHostBlobBytes, 0);
      const uint64_t total = kHostBlobBytes;
      std::memcpy(bytes.data() + 2 * VK_UUID_SIZE, &total, sizeof(total));  // the header's total size
    }
  }

  void Run(Reader& r) {
    for (step_ = 0; step_ < 256 && !r.empty(); ++step_) {
      Step(r);
      Compare();
    }
  }

 private:
  void Buffer(VkBuffer buffer, VkDeviceSize size, VkDeviceSize memory_offset) {
    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = size;
    info.usage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT |
                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    RecordCreateBuffer(state_, info, buffer);
    RecordBindBufferMemory(state_, dispatch_, Fake<VkDevice>(1), buffer, kMemory, memory_offset);
  }
  void Allocate(uint32_t i) {
    const VkCommandBuffer cb = CommandBuffer(i);
    state_.command_buffers.Allocate(
        VkCommandBufferAllocateInfo{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO, nullptr, kCommandPool,
                                    i < kPrimaries ? VK_COMMAND_BUFFER_LEVEL_PRIMARY : VK_COMMAND_BUFFER_LEVEL_SECONDARY,
                                    1},
        &cb);
    cbs_[i] = CommandBufferModel{};
  }

  void Create(Reader& r) {
    const uint32_t as = r.Below(kHandles);
    if (model_.structures[as].live) Destroy(as);  // the same handle value for a new structure
    const VkDeviceSize offset = kGrid * r.Below(kGridSteps);
    const VkDeviceSize size = kGrid * (1 + r.Below(4));
    const VkBuffer buffer = Fake<VkBuffer>(0x100 + next_buffer_++);
    Buffer(buffer, size, offset);
    VkAccelerationStructureCreateInfoKHR create{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
    create.buffer = buffer;
    create.size = size;
    create.type = VK_ACCELERATION_STRUCTURE_TYPE_GENERIC_KHR;
    RecordCreateAccelerationStructure(state_, dispatch_, Fake<VkDevice>(1), create, Handle(as));
    model_.Create(as, offset, offset + size);
  }
  void Destroy(uint32_t as) {
    RecordDestroyAccelerationStructure(state_, Handle(as));
    model_.Destroy(as);
  }

  // The command buffer an operation is recorded into, begun when it is not recording.
  uint32_t Recording(Reader& r) {
    const uint32_t i = r.Below(kCommandBuffers);
    if (!cbs_[i].allocated) Allocate(i);
    if (!cbs_[i].recording) Begin(i);
    return i;
  }
  void Begin(uint32_t i) {
    state_.command_buffers.Reset(CommandBuffer(i));
    CommandBufferModel& m = cbs_[i];
    m.recording = true;
    m.lost = false;
    m.ops.clear();
    m.published = false;
    m.published_ops.clear();
  }
  void End(uint32_t i) {
    CommandBufferModel& m = cbs_[i];
    if (!m.allocated || !m.recording) return;
    state_.command_buffers.End(CommandBuffer(i));
    m.recording = false;
    m.published = !m.ops.empty() || m.lost;
    m.published_lost = m.lost;
    m.published_ops = m.ops;
    m.ops.clear();
  }

  ModelOp SerializeOp(Reader& r, bool device, uint32_t* address_step) {
    ModelOp op;
    op.src = r.Below(kHandles);
    if (device) {
      op.kind = ModelOp::kSerializeDevice;
      *address_step = r.Below(kGridSteps);
      op.has_span = true;
      op.begin = kGrid * *address_step;
      op.end = kMemorySize;
    } else {
      op.kind = ModelOp::kSerializeHost;
      op.blob = r.Below(kHostBlobs);
    }
    return op;
  }

  void RecordDevice(Reader& r) {
    const uint32_t i = Recording(r);
    const VkCommandBuffer cb = CommandBuffer(i);
    CommandBufferModel& m = cbs_[i];
    const std::size_t first = m.ops.size();
    RecordDeviceOp(r, cb, m);
    for (std::size_t k = first; k < m.ops.size(); ++k) m.ops[k].recorded_at = model_.clock;
  }

  void RecordDeviceOp(Reader& r, VkCommandBuffer cb, CommandBufferModel& m) {
    switch (r.Below(6)) {
      case 0:
      case 1: {
        GeneratedBuild b;
        Generate(r, true, &b);
        RecordCmdBuild(state_, cb, b.op.indirect ? OpCommand::kCmdBuildIndirect : OpCommand::kCmdBuild, 1, &b.info,
                       b.op.indirect ? nullptr : &b.range_pointer);
        m.ops.push_back(b.op);
        break;
      }
      case 2: {
        ModelOp op;
        op.kind = ModelOp::kCopy;
        op.src = r.Below(kHandles);
        op.dst = r.Below(kHandles);
        VkCopyAccelerationStructureInfoKHR copy{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_INFO_KHR};
        copy.src = Handle(op.src);
        copy.dst = Handle(op.dst);
        op.compact = r.Bit();
        copy.mode = op.compact ? VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR : VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR;
        RecordCmdCopy(state_, cb, copy);
        m.ops.push_back(op);
        break;
      }
      case 3: {
        uint32_t at = 0;
        const ModelOp op = SerializeOp(r, true, &at);
        VkCopyAccelerationStructureToMemoryInfoKHR to{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_TO_MEMORY_INFO_KHR};
        to.src = Handle(op.src);
        to.dst.deviceAddress = DataAddress(at);
        to.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_SERIALIZE_KHR;
        RecordCmdCopyToMemory(state_, cb, to);
        m.ops.push_back(op);
        break;
      }
      case 4: {
        ModelOp op;
        op.kind = ModelOp::kDeserializeDevice;
        op.dst = r.Below(kHandles);
        VkCopyMemoryToAccelerationStructureInfoKHR from{VK_STRUCTURE_TYPE_COPY_MEMORY_TO_ACCELERATION_STRUCTURE_INFO_KHR};
        from.src.deviceAddress = DataAddress(r.Below(kGridSteps));
        from.dst = Handle(op.dst);
        from.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_DESERIALIZE_KHR;
        RecordCmdCopyMemoryTo(state_, cb, from);
        m.ops.push_back(op);
        break;
      }
      case 5: {
        const uint32_t count = 1 + r.Below(3);
        const uint32_t first = r.Below(kQueries - count + 1);
        const VkQueryType type = r.Bit() ? VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR
                                         : VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR;
        VkAccelerationStructureKHR structures[3];
        for (uint32_t k = 0; k < count; ++k) {
          ModelOp op;
          op.kind = ModelOp::kWriteProperties;
          op.dst = r.Below(kHandles);
          op.pool_query = first + k;
          op.query_type = type;
          structures[k] = Handle(op.dst);
          m.ops.push_back(op);
        }
        RecordCmdWriteProperties(state_, cb, count, structures, type, kPool, first);
        break;
      }
    }
  }
  static VkDeviceAddress DataAddress(uint32_t step) { return kDataBuffer * 0x100000 + kGrid * step; }

  void ExecuteSecondary(Reader& r) {
    const uint32_t primary = r.Below(kPrimaries);
    if (!cbs_[primary].allocated) Allocate(primary);
    if (!cbs_[primary].recording) Begin(primary);
    const uint32_t secondary = kPrimaries;
    const VkCommandBuffer handle = CommandBuffer(secondary);
    RecordExecuteCommands(state_, CommandBuffer(primary), 1, &handle);
    const CommandBufferModel& s = cbs_[secondary];
    CommandBufferModel& p = cbs_[primary];
    if (!s.allocated) {
      p.lost = true;
    } else if (s.published) {
      if (s.published_lost) p.lost = true;
      p.ops.insert(p.ops.end(), s.published_ops.begin(), s.published_ops.end());
    }
  }

  // The findings the history rules must give for `op` before it executes, from the model (update_rules.h; the
  // copies family's dst-03561 never fires here: every destination has room for the sizes read back).
  std::vector<std::string> Predict(const ModelOp& op) const {
    std::vector<std::string> out;
    const auto readable = [&](uint32_t as) -> const ModelHistory* {
      const ModelStructure& s = model_.structures[as];
      if (!s.live || s.history.kind == ModelKind::kUnknown) return nullptr;  // skipped and counted
      return &s.history;
    };
    switch (op.kind) {
      case ModelOp::kBuild: {
        if (!op.update) break;
        const ModelHistory* h = readable(op.src);
        if (!h) break;
        const std::string vuid = std::string("VUID-") +
                                 (op.indirect ? "vkCmdBuildAccelerationStructuresIndirectKHR-"
                                              : "vkCmdBuildAccelerationStructuresKHR-");
        if (h->clobbered) out.push_back(kClobberedId);
        if (h->kind == ModelKind::kNeverBuilt) {
          out.push_back(vuid + "pInfos-03667");
          break;
        }
        if (op.unreadable) break;
        const ModelParams& s = h->params;
        const ModelParams& u = op.params;
        if (!(s.flags & VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR)) out.push_back(vuid + "pInfos-03667");
        if (s.geometries.size() != u.geometries.size()) out.push_back(vuid + "pInfos-03758");
        if (s.flags != u.flags) out.push_back(vuid + "pInfos-03759");
        if (s.type != u.type) out.push_back(vuid + "pInfos-03760");
        for (size_t j = 0; j < std::min(s.geometries.size(), u.geometries.size()); ++j) {
          const ModelGeometry& b = s.geometries[j];
          const ModelGeometry& g = u.geometries[j];
          if (g.type != b.type) {
            out.push_back(vuid + "pInfos-03761");
            continue;
          }
          if (g.flags != b.flags) out.push_back(vuid + "pInfos-03762");
          if (g.type == VK_GEOMETRY_TYPE_TRIANGLES_KHR) {
            if (g.vertex_format != b.vertex_format) out.push_back(vuid + "pInfos-03763");
            if (g.max_vertex != b.max_vertex) out.push_back(vuid + "pInfos-03764");
            if (g.index_type != b.index_type) out.push_back(vuid + "pInfos-03765");
            if (!b.has_transform && g.has_transform) out.push_back(vuid + "pInfos-03766");
            if (b.has_transform && !g.has_transform) out.push_back(vuid + "pInfos-03767");
          }
          if (g.count_known && b.count_known && g.primitive_count != b.primitive_count) {
            out.push_back(vuid + "primitiveCount-03769");
          }
        }
        break;
      }
      case ModelOp::kCopy:
      case ModelOp::kSerializeDevice: {
        const ModelHistory* h = readable(op.src);
        if (!h) break;
        if (h->clobbered) out.push_back(kClobberedId);
        if (h->kind == ModelKind::kNeverBuilt) {
          out.push_back(op.kind == ModelOp::kCopy ? "VUID-VkCopyAccelerationStructureInfoKHR-src-04963"
                                                  : "VUID-VkCopyAccelerationStructureToMemoryInfoKHR-src-04959");
        } else if (op.kind == ModelOp::kCopy && op.compact && h->kind == ModelKind::kBuilt &&
                   !(h->params.flags & VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR)) {
          out.push_back("VUID-VkCopyAccelerationStructureInfoKHR-src-03411");
        }
        break;
      }
      case ModelOp::kWriteProperties: {
        const ModelHistory* h = readable(op.dst);
        if (!h) break;
        if (h->kind == ModelKind::kNeverBuilt) {
          out.push_back("VUID-vkCmdWriteAccelerationStructuresPropertiesKHR-pAccelerationStructures-04964");
        } else if (op.query_type == VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR &&
                   !(h->params.flags & VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR)) {
          out.push_back("VUID-vkCmdWriteAccelerationStructuresPropertiesKHR-accelerationStructures-03431");
        }
        break;
      }
      default:
        break;
    }
    std::sort(out.begin(), out.end());
    return out;
  }

  // vkQueueSubmit's history path: before each operation the rules run (their findings collected, not reported,
  // and compared with the model's prediction), then the operation is applied to the store and to the model.
  void Submit(Reader& r) {
    uint32_t order[3];
    const uint32_t count = 1 + r.Below(3);
    // Now and then a command buffer never allocated (kCommandBuffers): every structure's history becomes unknown,
    // which silences the rules, so rarely.
    for (uint32_t k = 0; k < count; ++k) {
      const uint8_t pick = r.Byte();
      order[k] = pick >= 248 ? kCommandBuffers : pick % kCommandBuffers;
    }
    const uint8_t outcome = r.Below(4);  // 0: the driver rejects it, 1: and a host operation completes meanwhile
    const Model before = model_;
    model_.BeginSubmission();
    {
      HistorySubmission submission(state_);
      for (uint32_t k = 0; k < count; ++k) {
        const VkCommandBuffer cb = CommandBuffer(order[k]);
        const HistoryCheckSite site{Location("vkQueueSubmit").Field("pSubmits", 0).Field("pCommandBuffers", k), cb,
                                    true};
        const bool known = order[k] < kCommandBuffers && cbs_[order[k]].allocated;
        const std::vector<ModelOp>* ops = known && cbs_[order[k]].published && !cbs_[order[k]].published_lost
                                              ? &cbs_[order[k]].published_ops
                                              : nullptr;
        size_t next = 0;
        submission.Apply(cb, [&](const HistoryStore& store, const OpBatch& batch, const AsOp& op) {
          if (!ops || next >= ops->size() || batch.ops().size() != ops->size()) {
            Mismatch(step_, "command buffer " + std::to_string(order[k]) + " submits " +
                                std::to_string(batch.ops().size()) + " recorded operations, model: " +
                                std::to_string(ops ? ops->size() : 0));
          }
          HistoryFindings findings;
          CheckOpHistory(state_, store, kAllChecks, batch, op, site, findings);
          std::vector<std::string> found;
          for (const HistoryFinding& f : findings.list()) found.push_back(f.vuid);
          std::sort(found.begin(), found.end());
          const ModelOp& mop = (*ops)[next++];
          const std::vector<std::string> expected = Predict(mop);
          if (found != expected) {
            std::string text;
            for (const std::string& v : found) text += " " + v;
            text += " | model:";
            for (const std::string& v : expected) text += " " + v;
            Mismatch(step_, "findings of operation " + std::to_string(next - 1) + " (kind " +
                                std::to_string(mop.kind) + ") of command buffer " + std::to_string(order[k]) +
                                ":" + text);
          }
          model_.Apply(mop, host_);
        });
        if (!known || (cbs_[order[k]].published && cbs_[order[k]].published_lost)) {
          model_.ApplyLost();
        } else if (ops && next != ops->size()) {
          Mismatch(step_, "command buffer " + std::to_string(order[k]) + ": " + std::to_string(next) +
                              " operations applied, model: " + std::to_string(ops->size()));
        }
      }
      submission.EndApply();
      model_.EndApply();
      if (outcome == 1) HostOperation(r);  // completes on another thread during the downcall
      if (outcome <= 1) {
        submission.Undo();
        model_.Undo(before);
      }
    }
  }

  // A host command, applied at once or deferred.
  void HostOperation(Reader& r) {
    OpBatch batch;
    ModelOp op;
    GeneratedBuild b;
    const uint32_t kind = r.Below(4);
    if (kind == 0) {
      Generate(r, false, &b);
      op = b.op;
      batch = HostBuildOps(1, &b.info, &b.range_pointer);
    } else if (kind == 1) {
      op.kind = ModelOp::kCopy;
      op.src = r.Below(kHandles);
      op.dst = r.Below(kHandles);
      VkCopyAccelerationStructureInfoKHR copy{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_INFO_KHR};
      copy.src = Handle(op.src);
      copy.dst = Handle(op.dst);
      copy.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR;
      batch = HostCopyOps(copy);
    } else if (kind == 2) {
      uint32_t unused = 0;
      op = SerializeOp(r, false, &unused);
      // The driver writes the serialized bytes (the header's size stays).
      std::vector<uint8_t>& bytes = host_[op.blob];
      const uint8_t seed = r.Byte();
      for (uint32_t i = 48; i < kHostBlobBytes; ++i) bytes[i] = static_cast<uint8_t>(seed + i * (op.src + 1));
      VkCopyAccelerationStructureToMemoryInfoKHR to{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_TO_MEMORY_INFO_KHR};
      to.src = Handle(op.src);
      to.dst.hostAddress = bytes.data();
      to.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_SERIALIZE_KHR;
      batch = HostCopyToMemoryOps(to);
    } else {
      op.kind = ModelOp::kDeserializeHost;
      op.blob = r.Below(kHostBlobs);
      op.dst = r.Below(kHandles);
      VkCopyMemoryToAccelerationStructureInfoKHR from{VK_STRUCTURE_TYPE_COPY_MEMORY_TO_ACCELERATION_STRUCTURE_INFO_KHR};
      from.src.hostAddress = host_[op.blob].data();
      from.dst = Handle(op.dst);
      from.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_DESERIALIZE_KHR;
      batch = HostCopyMemoryToOps(from);
    }
    const uint32_t how = r.Below(4);
    if (how == 0) {
      const uint32_t d = r.Below(kDeferred);
      FinishHostOps(state_, std::move(batch), Fake<VkDeferredOperationKHR>(0x900 + d), VK_OPERATION_DEFERRED_KHR);
      deferred_[d].push_back(op);
    } else if (how == 1) {
      FinishHostOps(state_, std::move(batch), VK_NULL_HANDLE, VK_ERROR_OUT_OF_HOST_MEMORY);  // failed: nothing
    } else {
      FinishHostOps(state_, std::move(batch), VK_NULL_HANDLE, VK_SUCCESS);
      model_.Apply(op, host_);
    }
  }

  void CompleteDeferred(Reader& r) {
    const uint32_t d = r.Below(kDeferred);
    const bool success = r.Below(4) != 0;
    CompleteDeferredOps(state_, Fake<VkDeferredOperationKHR>(0x900 + d), success ? VK_SUCCESS : VK_ERROR_UNKNOWN);
    if (success) {
      for (const ModelOp& op : deferred_[d]) model_.Apply(op, host_);
    }
    deferred_[d].clear();
  }

  void ReadBack(Reader& r) {
    if (r.Bit()) {
      // vkWriteAccelerationStructuresPropertiesKHR: a serialization size of the current contents.
      const uint32_t as = r.Below(kHandles);
      const uint64_t size = kGrid / 4 * r.Below(12);
      const VkAccelerationStructureKHR handle = Handle(as);
      RecordHostSerializationSizes(state_, 1, &handle, &size, sizeof(size));
      model_.ReadBackSize(as, model_.structures[as].history.contents, size);
      return;
    }
    // vkGetQueryPoolResults of serialization-size queries, 64-bit values with availability.
    const uint32_t count = 1 + r.Below(kQueries);
    const uint32_t first = r.Below(kQueries - count + 1);
    std::vector<uint64_t> data(2 * count);
    for (uint32_t k = 0; k < count; ++k) {
      data[2 * k] = kGrid / 4 * r.Below(12);
      data[2 * k + 1] = r.Below(4) != 0;
    }
    RecordQueryResults(state_, kPool, first, count, data.size() * sizeof(uint64_t), data.data(), 16,
                       VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WITH_AVAILABILITY_BIT, VK_SUCCESS);
    for (uint32_t k = 0; k < count; ++k) {
      const auto slot = model_.slots.find(first + k);
      if (slot == model_.slots.end() || !data[2 * k + 1] ||
          slot->second.type != VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR) {
        continue;
      }
      model_.ReadBackSize(slot->second.as, slot->second.contents, data[2 * k]);
    }
  }

  void Step(Reader& r) {
    switch (r.Below(12)) {
      case 0:
        Create(r);
        break;
      case 1: {
        const uint32_t as = r.Below(kHandles);
        if (model_.structures[as].live) Destroy(as);
        break;
      }
      case 2:
      case 3:
      case 4:
        RecordDevice(r);
        break;
      case 5:
        End(r.Below(kCommandBuffers));
        break;
      case 6:
      case 7:
        Submit(r);
        break;
      case 8:
        HostOperation(r);
        break;
      case 9:
        if (r.Bit()) {
          CompleteDeferred(r);
        } else {
          // The app rewrites a host array's bytes (not its header).
          host_[r.Below(kHostBlobs)][48 + r.Below(kHostBlobBytes - 48)] ^= static_cast<uint8_t>(1 + r.Byte() % 255);
        }
        break;
      case 10:
        ReadBack(r);
        break;
      case 11: {
        const uint32_t what = r.Below(3);
        if (what == 0) {
          ExecuteSecondary(r);
        } else {
          // Freed (submitting it now is submitting a command buffer the layer does not know), maybe reallocated.
          const uint32_t i = r.Below(kCommandBuffers);
          const VkCommandBuffer cb = CommandBuffer(i);
          state_.command_buffers.Free(1, &cb);
          cbs_[i] = CommandBufferModel{};
          cbs_[i].allocated = false;
          if (what == 2) Allocate(i);
        }
        break;
      }
    }
  }

  // ---- comparison ----
  static const char* KindName(ModelKind k) {
    return k == ModelKind::kNeverBuilt ? "never built" : k == ModelKind::kBuilt ? "built" : "unknown";
  }
  static ModelKind KindOf(HistoryKind k) {
    return k == HistoryKind::kNeverBuilt ? ModelKind::kNeverBuilt
           : k == HistoryKind::kBuilt    ? ModelKind::kBuilt
                                         : ModelKind::kUnknown;
  }
  static ModelUnknown ReasonOf(UnknownReason u) {
    switch (u) {
      case UnknownReason::kNone: return ModelUnknown::kNone;
      case UnknownReason::kDeserializedUnknownBytes: return ModelUnknown::kDeserializedUnknownBytes;
      case UnknownReason::kDeserializedDeviceBytes: return ModelUnknown::kDeserializedDeviceBytes;
      case UnknownReason::kCopiedFromUnknown: return ModelUnknown::kCopiedFromUnknown;
      case UnknownReason::kLostOperations: return ModelUnknown::kLostOperations;
      case UnknownReason::kUnreadableBuild: return ModelUnknown::kUnreadableBuild;
      case UnknownReason::kStaleHandle: return ModelUnknown::kStaleHandle;
    }
    return ModelUnknown::kNone;
  }
  // Empty when the snapshot holds exactly the model's parameters.
  static std::string DiffParams(const BuildSnapshot* s, const ModelParams& m) {
    if (!s) return "no build snapshot";
    if (s->flags != m.flags) return "flags " + std::to_string(s->flags) + " vs " + std::to_string(m.flags);
    if (s->type != m.type) return "type " + std::to_string(s->type) + " vs " + std::to_string(m.type);
    if (s->geometries.size() != m.geometries.size()) {
      return "geometryCount " + std::to_string(s->geometries.size()) + " vs " + std::to_string(m.geometries.size());
    }
    for (size_t j = 0; j < m.geometries.size(); ++j) {
      const GeometryRecord& g = s->geometries[j];
      const ModelGeometry& e = m.geometries[j];
      const bool same = g.type == e.type && g.flags == e.flags && g.vertex_format == e.vertex_format &&
                        g.index_type == e.index_type && g.max_vertex == e.max_vertex &&
                        g.has_transform == e.has_transform && g.primitive_count_known == e.count_known &&
                        (!e.count_known || g.primitive_count == e.primitive_count);
      if (!same) {
        return "geometry " + std::to_string(j) + " (type " + std::to_string(g.type) + "/" + std::to_string(e.type) +
               ", count " + std::to_string(g.primitive_count) + "/" + std::to_string(e.primitive_count) + ", known " +
               std::to_string(g.primitive_count_known) + "/" + std::to_string(e.count_known) + ")";
      }
    }
    return {};
  }
  void CompareHistory(const std::string& what, const AsHistory* h, const ModelHistory& m) {
    const ModelKind kind = h ? KindOf(h->kind) : ModelKind::kNeverBuilt;
    if (kind != m.kind) Mismatch(step_, what + ": " + KindName(kind) + ", model: " + KindName(m.kind));
    if (!h) return;
    if (ReasonOf(h->unknown_reason) != m.reason) {
      Mismatch(step_, what + ": unknown reason " + std::to_string(static_cast<int>(h->unknown_reason)) +
                          ", model: " + std::to_string(static_cast<int>(m.reason)));
    }
    if (m.kind == ModelKind::kBuilt) {
      const std::string diff = DiffParams(h->build.get(), m.params);
      if (!diff.empty()) Mismatch(step_, what + ": last build's parameters differ: " + diff);
    }
  }
  void Compare() {
    HistoryStore& store = state_.history.store;
    auto lock = store.Lock();
    size_t records = 0;
    for (uint32_t as = 0; as < kHandles; ++as) {
      const ModelStructure& m = model_.structures[as];
      const AsHistory* h = store.Find(Handle(as));
      const std::string name = "structure " + std::to_string(as);
      if (!m.live && h) Mismatch(step_, name + " is destroyed but has a history record");
      CompareHistory(name, h, m.history);
      if (!h) continue;
      ++records;
      if (h->clobbered.has_value() != m.history.clobbered) {
        Mismatch(step_, name + ": clobbered " + std::to_string(h->clobbered.has_value()) + ", model: " +
                            std::to_string(m.history.clobbered));
      }
      const bool size_known = h->serialization_size_generation != 0 && h->serialization_size_generation == h->generation;
      if (size_known != m.history.serialization_size.has_value() ||
          (size_known && h->serialization_size != *m.history.serialization_size)) {
        Mismatch(step_, name + ": serialization size known " + std::to_string(size_known) + " (" +
                            std::to_string(h->serialization_size) + "), model: " +
                            std::to_string(m.history.serialization_size.has_value()));
      }
    }
    if (records != store.size()) {
      Mismatch(step_, std::to_string(store.size()) + " records, model: " + std::to_string(records));
    }
    for (uint32_t q = 0; q < kQueries; ++q) {
      const QuerySlot* slot = store.FindSlot(kPool, q);
      const auto m = model_.slots.find(q);
      const std::string name = "query slot " + std::to_string(q);
      if (!slot != (m == model_.slots.end())) Mismatch(step_, name + ": present " + std::to_string(slot != nullptr));
      if (!slot) continue;
      if (slot->as != Handle(m->second.as) || slot->type != m->second.type) Mismatch(step_, name + ": other structure or type");
      const AsHistory* h = store.Find(slot->as);
      const bool fresh = slot->generation != 0 && h && h->generation == slot->generation;
      const ModelStructure& s = model_.structures[m->second.as];
      const bool model_fresh = m->second.contents != 0 && s.live && s.history.contents == m->second.contents;
      if (fresh != model_fresh) Mismatch(step_, name + ": measures the current contents " + std::to_string(fresh));
    }
    for (uint32_t b = 0; b < kHostBlobs; ++b) {
      const SerializedBlob* blob = store.FindHostBlob(host_[b].data());
      const ModelBlob* m = model_.LatestHostBlob(b);
      const std::string name = "host bytes " + std::to_string(b);
      if (!blob != !m) Mismatch(step_, name + ": serialized " + std::to_string(blob != nullptr));
      if (blob) CompareHistory(name + "'s serialized structure", &blob->history, m->history);
    }
    for (uint32_t g = 0; g < kGridSteps; ++g) {
      const SerializedBlob* blob = store.FindDeviceBlob(MemorySpan{kMemory, kGrid * g, kGrid * g});
      const ModelBlob* m = model_.LatestDeviceBlob(kGrid * g);
      const std::string name = "device bytes at " + std::to_string(kGrid * g);
      if (!blob != !m) Mismatch(step_, name + ": serialized " + std::to_string(blob != nullptr));
      if (!blob) continue;
      if (blob->span.end != m->end) Mismatch(step_, name + ": end " + std::to_string(blob->span.end));
      CompareHistory(name + "'s serialized structure", &blob->history, m->history);
    }
  }

  DeviceState state_;
  DeviceDispatchTable dispatch_{};
  Model model_;
  CommandBufferModel cbs_[kCommandBuffers];
  std::vector<uint8_t> host_[kHostBlobs];
  std::vector<ModelOp> deferred_[kDeferred];
  uint32_t next_buffer_ = 0;
  int step_ = 0;
};

}  // namespace
}  // namespace asval::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  asval::fuzz::Reader r{data, size};
  asval::fuzz::Harness harness;
  harness.Run(r);
  return 0;
}
