#include "inject.h"

#include <algorithm>
#include <cstdio>
#include <functional>
#include <stdexcept>
#include <deque>
#include <utility>

namespace scene {

namespace {

constexpr VkBuildAccelerationStructureModeKHR kBuild = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
constexpr VkBuildAccelerationStructureModeKHR kUpdate = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;

// Resources a fault creates; released after the GPU is idle.
struct Scratchpad {
  explicit Scratchpad(Gpu& g) : gpu(g) {}
  ~Scratchpad() {
    vkDeviceWaitIdle(gpu.device());
    for (Buffer& b : buffers) gpu.Destroy(b);
    for (AccelerationStructure& as : structures) gpu.Destroy(as);
  }
  Buffer& NewScratch(VkDeviceSize size) {
    buffers.push_back(gpu.CreateBuffer(std::max<VkDeviceSize>(size, 4), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                       Memory::kDeviceLocal));
    gpu.Name(VK_OBJECT_TYPE_BUFFER, buffers.back().buffer, "fault scratch");
    return buffers.back();
  }
  AccelerationStructure& NewStructure(VkAccelerationStructureTypeKHR type, VkDeviceSize size, const char* name) {
    structures.push_back(gpu.CreateAccelerationStructure(type, size, name));
    return structures.back();
  }
  Gpu& gpu;
  std::deque<Buffer> buffers;  // deques: references stay valid as they grow
  std::deque<AccelerationStructure> structures;
};

class Injector {
 public:
  Injector(Scene& scene, const FaultInfo& fault)
      : s_(scene), gpu_(scene.gpu), fault_(fault), parity_(scene.frames_done() % 2), pad_(scene.gpu) {
    s_.deforming.params().time = Scene::TimeOf(scene.frames_done());
  }

  void Run();

 private:
  // Records one command buffer and submits it. A fault marked `withheld` is submitted only when asval announced,
  // while it was recorded, that it withheld the invalid command (protect mode: ASVAL-Protect-Withheld); the
  // command buffer is then marked and asval withholds its submission too. Without that notice (no asval, or
  // protect off) the command would reach the driver, so the scene never submits it.
  void RecordAndSubmit(const std::function<void(VkCommandBuffer)>& record) {
    const uint32_t notices_before = s_.findings.withheld_notices();
    VkCommandBuffer cb = Record(record);
    if (fault_.withheld && s_.findings.withheld_notices() == notices_before) {
      std::printf("fault: no %s notice while recording; the command buffer is withheld by the scene (executing it "
                  "could corrupt memory or hang the device)\n", kWithheldNoticeId);
    } else {
      if (fault_.withheld) std::printf("fault: asval withheld the command while recording; submitting its buffer\n");
      Submit({cb});
    }
    gpu_.FreeCommandBuffer(cb);
  }

  VkCommandBuffer Record(const std::function<void(VkCommandBuffer)>& record) {
    VkCommandBuffer cb = gpu_.AllocateCommandBuffer();
    gpu_.Begin(cb, VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT);
    record(cb);
    gpu_.End(cb);
    return cb;
  }

  // In protect mode asval withholds a submission that holds a withheld command or breaks a rule in execution
  // order: it returns VK_ERROR_VALIDATION_FAILED_EXT and announces it. That is the expected outcome of a fault,
  // and the scene goes on; any other failure is the scene's own.
  void Submit(std::initializer_list<VkCommandBuffer> cbs) {
    const uint32_t notices_before = s_.findings.withheld_notices();
    const VkResult result = gpu_.SubmitAndWait(cbs);
    if (result == VK_SUCCESS) return;
    if (result == VK_ERROR_VALIDATION_FAILED_EXT && s_.findings.withheld_notices() > notices_before) {
      std::printf("fault: asval withheld the submission (VK_ERROR_VALIDATION_FAILED_EXT)\n");
      return;
    }
    Check(result, "fault: vkQueueSubmit");
  }

  void BuildInto(VkCommandBuffer cb, const BuildInput& input, VkAccelerationStructureKHR dst, VkDeviceAddress scratch) {
    RecordBuild(gpu_, cb, {input.Info(kBuild, VK_NULL_HANDLE, dst, scratch)}, {&input});
  }

  // A spare bottom-level structure: the ground built again into a structure of the scratchpad, submitted and waited.
  AccelerationStructure& SpareGround() {
    const BuildInput& ground = s_.statics.input(StaticBlases::kGround);
    const VkAccelerationStructureBuildSizesInfoKHR sizes = ground.QuerySizes(gpu_);
    AccelerationStructure& spare =
        pad_.NewStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, sizes.accelerationStructureSize, "spare");
    const Buffer& scratch = pad_.NewScratch(sizes.buildScratchSize);
    RecordAndSubmit([&](VkCommandBuffer cb) { BuildInto(cb, ground, spare.handle, scratch.address); });
    return spare;
  }

  // The next frame's instances written, with the first active one after instance 0 made to reference `reference`:
  // returns its index.
  uint32_t ReferenceFromNextFrame(VkDeviceAddress reference) {
    s_.top.WriteInstances(parity_, Scene::TimeOf(s_.frames_done()));
    VkAccelerationStructureInstanceKHR* instances = s_.top.instances(parity_);
    uint32_t victim = 1;
    while (victim < s_.top.count() && instances[victim].accelerationStructureReference == 0) ++victim;
    instances[victim].accelerationStructureReference = reference;
    return victim;
  }

  void UpdateWithoutSource();
  void BottomIntoTopObject();
  void VertexStride();
  void ScratchMisaligned();
  void ScratchTooSmall();
  void DestinationTooSmall();
  void ScratchOverlap();
  void CopyModeInvalid();
  void UpdateGeometryCount();
  void UpdateFlags();
  void UpdateReordered();
  void UpdateActivates();
  void UpdateIndices();
  void DestroyedInstance();
  void QueryWithoutCompaction();
  void ScratchDestroyedPending();
  void TracedUnbuilt();
  void TracedBlasDestroyed();

  Scene& s_;
  Gpu& gpu_;
  const FaultInfo& fault_;
  const uint32_t parity_;  // of the next frame: its vertex and instance buffers are free to use
  Scratchpad pad_;
};

void Injector::Run() {
  switch (fault_.id) {
    case FaultId::kUpdateWithoutSource: return UpdateWithoutSource();
    case FaultId::kBottomIntoTopObject: return BottomIntoTopObject();
    case FaultId::kVertexStride: return VertexStride();
    case FaultId::kScratchMisaligned: return ScratchMisaligned();
    case FaultId::kScratchTooSmall: return ScratchTooSmall();
    case FaultId::kDestinationTooSmall: return DestinationTooSmall();
    case FaultId::kScratchOverlap: return ScratchOverlap();
    case FaultId::kCopyModeInvalid: return CopyModeInvalid();
    case FaultId::kUpdateGeometryCount: return UpdateGeometryCount();
    case FaultId::kUpdateFlags: return UpdateFlags();
    case FaultId::kUpdateReordered: return UpdateReordered();
    case FaultId::kUpdateActivates: return UpdateActivates();
    case FaultId::kUpdateIndices: return UpdateIndices();
    case FaultId::kDestroyedInstance: return DestroyedInstance();
    case FaultId::kQueryWithoutCompaction: return QueryWithoutCompaction();
    case FaultId::kScratchDestroyedPending: return ScratchDestroyedPending();
    case FaultId::kTracedUnbuilt: return TracedUnbuilt();
    case FaultId::kTracedBlasDestroyed: return TracedBlasDestroyed();
  }
}

void Injector::UpdateWithoutSource() {
  const BuildInput blob = s_.deforming.BlobInput(parity_);
  RecordAndSubmit([&](VkCommandBuffer cb) {
    RecordBuild(gpu_, cb, {blob.Info(kUpdate, VK_NULL_HANDLE, s_.deforming.blob().handle, s_.deforming.blob_scratch())},
                {&blob});
  });
}

void Injector::BottomIntoTopObject() {
  const BuildInput blob = s_.deforming.BlobInput(parity_);
  const VkAccelerationStructureBuildSizesInfoKHR sizes = blob.QuerySizes(gpu_);
  AccelerationStructure& dst = pad_.NewStructure(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR,
                                                 sizes.accelerationStructureSize, "blob copy, created as top-level");
  const Buffer& scratch = pad_.NewScratch(sizes.buildScratchSize);
  RecordAndSubmit([&](VkCommandBuffer cb) { BuildInto(cb, blob, dst.handle, scratch.address); });
}

void Injector::VertexStride() {
  const BuildInput& rock = s_.statics.input(StaticBlases::kRock);
  const VkAccelerationStructureBuildSizesInfoKHR sizes = rock.QuerySizes(gpu_);  // the stride changes no size
  BuildInput bad = rock;
  bad.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
  bad.geometries[0].geometry.triangles.vertexStride = 30;  // reads stay inside the 32-byte vertices' range
  AccelerationStructure& dst =
      pad_.NewStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, sizes.accelerationStructureSize, "rock copy");
  const Buffer& scratch = pad_.NewScratch(sizes.buildScratchSize);
  RecordAndSubmit([&](VkCommandBuffer cb) { BuildInto(cb, bad, dst.handle, scratch.address); });
}

void Injector::ScratchMisaligned() {
  const VkDeviceSize alignment = gpu_.as_properties().minAccelerationStructureScratchOffsetAlignment;
  if (alignment < 2) throw std::runtime_error("scratch-misaligned: this device needs no scratch alignment");
  const BuildInput blob = s_.deforming.BlobInput(parity_);
  const VkAccelerationStructureBuildSizesInfoKHR sizes = blob.QuerySizes(gpu_);
  const Buffer& scratch = pad_.NewScratch(sizes.buildScratchSize + 2 * alignment);
  // Aligned start, moved by half the alignment; the whole range stays inside the buffer.
  const VkDeviceAddress address = AlignUp(scratch.address, alignment) + alignment / 2;
  std::printf("fault: scratch at 0x%llx, the device requires multiples of %llu\n",
              static_cast<unsigned long long>(address), static_cast<unsigned long long>(alignment));
  RecordAndSubmit([&](VkCommandBuffer cb) { BuildInto(cb, blob, s_.deforming.blob().handle, address); });
}

void Injector::ScratchTooSmall() {
  const BuildInput blob = s_.deforming.BlobInput(parity_);
  const VkAccelerationStructureBuildSizesInfoKHR sizes = blob.QuerySizes(gpu_);
  if (sizes.buildScratchSize < 2) throw std::runtime_error("scratch-too-small: the driver needs no build scratch");
  const Buffer& scratch = pad_.NewScratch(sizes.buildScratchSize / 2);
  std::printf("fault: scratch buffer of %llu bytes, the build needs %llu\n",
              static_cast<unsigned long long>(scratch.size), static_cast<unsigned long long>(sizes.buildScratchSize));
  RecordAndSubmit([&](VkCommandBuffer cb) { BuildInto(cb, blob, s_.deforming.blob().handle, scratch.address); });
}

void Injector::DestinationTooSmall() {
  const BuildInput blob = s_.deforming.BlobInput(parity_);
  const VkAccelerationStructureBuildSizesInfoKHR sizes = blob.QuerySizes(gpu_);
  const VkDeviceSize half = AlignUp(sizes.accelerationStructureSize / 2, 256);
  if (half >= sizes.accelerationStructureSize) throw std::runtime_error("dst-too-small: structure size too small");
  AccelerationStructure& dst =
      pad_.NewStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, half, "blob copy, half size");
  const Buffer& scratch = pad_.NewScratch(sizes.buildScratchSize);
  std::printf("fault: destination of %llu bytes, the build needs %llu\n", static_cast<unsigned long long>(half),
              static_cast<unsigned long long>(sizes.accelerationStructureSize));
  RecordAndSubmit([&](VkCommandBuffer cb) { BuildInto(cb, blob, dst.handle, scratch.address); });
}

void Injector::ScratchOverlap() {
  const BuildInput flag = s_.deforming.FlagInput(parity_), blob = s_.deforming.BlobInput(parity_);
  const VkDeviceSize size = std::max(flag.QuerySizes(gpu_).buildScratchSize, blob.QuerySizes(gpu_).buildScratchSize);
  const Buffer& scratch = pad_.NewScratch(size);
  RecordAndSubmit([&](VkCommandBuffer cb) {
    RecordBuild(gpu_, cb,
                {flag.Info(kBuild, VK_NULL_HANDLE, s_.deforming.flag().handle, scratch.address),
                 blob.Info(kBuild, VK_NULL_HANDLE, s_.deforming.blob().handle, scratch.address)},
                {&flag, &blob});
  });
}

void Injector::CopyModeInvalid() {
  AccelerationStructure& dst = pad_.NewStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
                                                 s_.deforming.blob().size, "blob copy");
  RecordAndSubmit([&](VkCommandBuffer cb) {
    VkCopyAccelerationStructureInfoKHR copy{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_INFO_KHR};
    copy.src = s_.deforming.blob().handle;
    copy.dst = dst.handle;
    copy.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_SERIALIZE_KHR;
    gpu_.vk().CmdCopyAccelerationStructureKHR(cb, &copy);
  });
}

void Injector::UpdateGeometryCount() {
  // The structure and its scratch slice are sized for this variant (see DeformingBlases), so only the
  // geometry count is wrong.
  const BuildInput flag = WithEmptyGeometry(s_.deforming.FlagInput(parity_));
  const AccelerationStructure& as = s_.deforming.flag();
  RecordAndSubmit([&](VkCommandBuffer cb) {
    s_.deforming.RecordAnimate(cb, parity_);
    RecordBuild(gpu_, cb, {flag.Info(kUpdate, as.handle, as.handle, s_.deforming.flag_scratch())}, {&flag});
  });
}

void Injector::UpdateFlags() {
  const BuildInput blob = DeformingBlases::WithCompactionFlag(s_.deforming.BlobInput(parity_));
  const AccelerationStructure& as = s_.deforming.blob();
  RecordAndSubmit([&](VkCommandBuffer cb) {
    s_.deforming.RecordAnimate(cb, parity_);
    RecordBuild(gpu_, cb, {blob.Info(kUpdate, as.handle, as.handle, s_.deforming.blob_scratch())}, {&blob});
  });
}

void Injector::UpdateReordered() {
  const AccelerationStructure& as = s_.deforming.blob();
  const BuildInput same = s_.deforming.BlobInput(parity_);
  const BuildInput other = DeformingBlases::WithCompactionFlag(same);
  // Recorded first: an update that matches the build the blob has now.
  VkCommandBuffer update = Record([&](VkCommandBuffer cb) {
    RecordBuild(gpu_, cb, {same.Info(kUpdate, as.handle, as.handle, s_.deforming.blob_scratch())}, {&same});
  });
  // Recorded second: a rebuild with other flags (valid by itself).
  VkCommandBuffer rebuild = Record([&](VkCommandBuffer cb) {
    s_.deforming.RecordAnimate(cb, parity_);
    RecordBuild(gpu_, cb, {other.Info(kBuild, VK_NULL_HANDLE, as.handle, s_.deforming.blob_scratch())}, {&other});
    Barrier(cb, kBuildStage, kBuildWrites, kBuildStage, kBuildReads);
  });
  std::printf("fault: submitting the rebuild (recorded second), then the update (recorded first)\n");
  Submit({rebuild});
  Submit({update});
  gpu_.FreeCommandBuffer(update);
  gpu_.FreeCommandBuffer(rebuild);
}

void Injector::UpdateActivates() {
  // The regular refit command buffer; only the data changes: the shader stops writing NaN.
  s_.deforming.params().revive_dead = 1;
  Submit({s_.refit_commands(parity_)});
  s_.deforming.params().revive_dead = 0;
}

void Injector::UpdateIndices() {
  // The regular refit command buffer; only the data changes. (a, b, c) -> (b, c, a) keeps every triangle
  // (and so its activity) but changes each index value.
  uint32_t* indices = s_.deforming.cloth_indices();
  const size_t count = s_.deforming.meshes().cloth.indices.size();
  for (size_t i = 0; i + 2 < count; i += 3) {
    const uint32_t a = indices[i];
    indices[i] = indices[i + 1];
    indices[i + 1] = indices[i + 2];
    indices[i + 2] = a;
  }
  Submit({s_.refit_commands(parity_)});
}

void Injector::DestroyedInstance() {
  // A spare structure, built validly, whose handle is then destroyed while its memory stays allocated.
  AccelerationStructure& spare = SpareGround();
  const VkDeviceAddress stale = spare.address;
  gpu_.DestroyHandle(spare);
  const uint32_t victim = ReferenceFromNextFrame(stale);
  std::printf("fault: instance %u references the destroyed structure (0x%llx)\n", victim,
              static_cast<unsigned long long>(stale));
  RecordAndSubmit([&](VkCommandBuffer cb) { s_.top.RecordBuild(cb, parity_, kBuild); });
}

void Injector::QueryWithoutCompaction() {
  VkQueryPoolCreateInfo info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  info.queryType = VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR;
  info.queryCount = 1;
  VkQueryPool pool = VK_NULL_HANDLE;
  Check(vkCreateQueryPool(gpu_.device(), &info, nullptr, &pool), "vkCreateQueryPool");
  const VkAccelerationStructureKHR blob = s_.deforming.blob().handle;
  RecordAndSubmit([&](VkCommandBuffer cb) {
    vkCmdResetQueryPool(cb, pool, 0, 1);
    gpu_.vk().CmdWriteAccelerationStructuresPropertiesKHR(cb, 1, &blob,
                                                          VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, pool, 0);
  });
  vkDestroyQueryPool(gpu_.device(), pool, nullptr);
}

void Injector::ScratchDestroyedPending() {
  // A build of a spare structure that waits for an event the host sets only after the scratch buffer's handle is
  // destroyed: the build is certainly pending then. The memory stays allocated until the build completed, so the
  // build reads and writes live memory whether or not asval keeps the destroy back (protect mode does).
  const BuildInput& ground = s_.statics.input(StaticBlases::kGround);
  const VkAccelerationStructureBuildSizesInfoKHR sizes = ground.QuerySizes(gpu_);
  AccelerationStructure& spare =
      pad_.NewStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, sizes.accelerationStructureSize, "spare");
  Buffer& scratch = pad_.NewScratch(sizes.buildScratchSize);
  VkEventCreateInfo event_info{VK_STRUCTURE_TYPE_EVENT_CREATE_INFO};
  VkEvent go = VK_NULL_HANDLE;
  Check(vkCreateEvent(gpu_.device(), &event_info, nullptr, &go), "vkCreateEvent");
  VkCommandBuffer build = Record([&](VkCommandBuffer cb) {
    vkCmdWaitEvents(cb, 1, &go, VK_PIPELINE_STAGE_HOST_BIT, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, 0,
                    nullptr, 0, nullptr, 0, nullptr);
    BuildInto(cb, ground, spare.handle, scratch.address);
  });
  VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence fence = VK_NULL_HANDLE;
  Check(vkCreateFence(gpu_.device(), &fence_info, nullptr, &fence), "vkCreateFence");
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &build;
  Check(vkQueueSubmit(gpu_.queue(), 1, &submit, fence), "vkQueueSubmit");
  std::printf("fault: destroying the scratch buffer of a submitted build that has not run yet\n");
  vkDestroyBuffer(gpu_.device(), scratch.buffer, nullptr);
  scratch.buffer = VK_NULL_HANDLE;  // its memory is freed with the scratchpad, after the GPU is idle
  Check(vkSetEvent(gpu_.device(), go), "vkSetEvent");
  Check(vkWaitForFences(gpu_.device(), 1, &fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
  vkDestroyFence(gpu_.device(), fence, nullptr);
  vkDestroyEvent(gpu_.device(), go, nullptr);
  gpu_.FreeCommandBuffer(build);
}

}  // namespace

void InjectFault(Scene& scene, const FaultInfo& fault) {
  std::printf("fault: injecting %s (%s): %s\n", fault.name, fault.vuid, fault.what);
  std::fflush(stdout);
  Injector(scene, fault).Run();
  std::fflush(stdout);
}

void Injector::TracedUnbuilt() {
  // A second handle over the bytes of the scene's top level, never built itself: the rule is about the structure
  // the descriptor names (no build executed on it), while the device reads a valid top level either way.
  const AccelerationStructure& top = s_.top.structure();
  VkAccelerationStructureCreateInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
  info.buffer = top.storage.buffer;
  info.size = top.size;
  info.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
  VkAccelerationStructureKHR unbuilt = VK_NULL_HANDLE;
  Check(gpu_.vk().CreateAccelerationStructureKHR(gpu_.device(), &info, nullptr, &unbuilt),
        "vkCreateAccelerationStructureKHR");
  s_.tracer.SetScene(unbuilt);
  std::printf("fault: tracing through a top-level structure no build executed on\n");
  RecordAndSubmit([&](VkCommandBuffer cb) { s_.tracer.RecordTrace(cb); });
  s_.tracer.SetScene(top.handle);
  gpu_.vk().DestroyAccelerationStructureKHR(gpu_.device(), unbuilt, nullptr);
}

void Injector::TracedBlasDestroyed() {
  // A spare bottom level (the ground, built again), referenced by one instance of a valid top-level rebuild that
  // completes; then the spare's handle is destroyed while its memory stays allocated, and the frame is traced: the
  // top level's instance still names the destroyed structure, whose bytes a driver that ran the trace would find.
  AccelerationStructure& spare = SpareGround();
  const uint32_t victim = ReferenceFromNextFrame(spare.address);
  RecordAndSubmit([&](VkCommandBuffer cb) { s_.top.RecordBuild(cb, parity_, kBuild); });  // valid, waited for
  gpu_.DestroyHandle(spare);
  std::printf("fault: tracing a top level whose instance %u references a bottom level destroyed since\n", victim);
  RecordAndSubmit([&](VkCommandBuffer cb) { s_.tracer.RecordTrace(cb); });
}

}  // namespace scene
