// A fixed list of jobs (builds, in-place and src != dst updates, clones and compactions, compacted-size queries,
// top-level builds, some with one deliberate fault each) run once on one thread, then by threads at once, as an
// engine's frame does: 4 threads record, each job into a command pool of its own; 2 threads submit them to the one
// queue (under the app's lock, as vkQueueSubmit requires) and wait for each submission's fence; 2 threads destroy
// finished jobs' objects and, meanwhile, create and destroy buffers, memory and structures no job uses. Both runs
// must report exactly the faults: each fault's VUID once, naming the command buffer of the job that made it, and
// nothing about valid work; a finding made when a submission completed must have arrived when the app's wait for
// that submission returns, whichever thread's call processed the completion. Under ThreadSanitizer (the tsan
// preset) this is the layer's stress test of recording, submission, completion and destruction racing each other.
#include <catch2/catch_test_macros.hpp>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "history_helpers.h"

namespace asval_test {
namespace {

enum class Kind {
  // Valid work.
  kBuildThenUpdateInPlace,
  kUpdateIntoOther,
  kCloneThenUpdate,
  kCompact,  // build, compacted-size query; once read, a compacting copy into a structure of that size
  kTopLevel,
  // One deliberate fault each (the rest of the job is valid).
  kUpdateWithoutAllowUpdate,
  kUpdateChangesGeometryCount,
  kScratchTooSmall,
  kScratchMisaligned,
  kDestinationTooSmall,
  kCloneOntoAlias,
  kCompactOntoAlias,
  kQueryPastPool,
  kInstanceOfDestroyed,  // a top-level build, submitted after a structure its instances reference was destroyed
};

struct KindInfo {
  Kind kind;
  const char* name;
  const char* vuid;  // the fault's one finding; null for valid work
  size_t phases;     // command buffers submitted one after the other, each waited for
  size_t fault_phase;
  bool at_completion = false;  // reported once the fault phase's submission completed, before its wait returns
};

// Faults found when the command is recorded skip that command; faults found at submission skip the submission;
// 06707 is judged on the instances the device read, once the submission completed (the build runs).
constexpr KindInfo kKinds[] = {
    {Kind::kBuildThenUpdateInPlace, "build-update-in-place", nullptr, 1, 0},
    {Kind::kUpdateIntoOther, "update-into-other", nullptr, 1, 0},
    {Kind::kCloneThenUpdate, "clone-then-update", nullptr, 1, 0},
    {Kind::kCompact, "compact", nullptr, 2, 0},
    {Kind::kTopLevel, "top-level", nullptr, 1, 0},
    {Kind::kUpdateWithoutAllowUpdate, "update-without-allow-update",
     "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03667", 1, 0},
    {Kind::kUpdateChangesGeometryCount, "update-changes-geometry-count",
     "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03758", 1, 0},
    {Kind::kScratchTooSmall, "scratch-too-small", "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03671", 1, 0},
    {Kind::kScratchMisaligned, "scratch-misaligned", "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710", 1, 0},
    {Kind::kDestinationTooSmall, "destination-too-small", "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-10126", 1,
     0},
    {Kind::kCloneOntoAlias, "clone-onto-alias", "VUID-VkCopyAccelerationStructureInfoKHR-dst-07791", 1, 0},
    {Kind::kCompactOntoAlias, "compact-onto-alias", "VUID-VkCopyAccelerationStructureInfoKHR-dst-07791", 1, 0},
    {Kind::kQueryPastPool, "query-past-pool", "VUID-vkCmdWriteAccelerationStructuresPropertiesKHR-query-04880", 1,
     0},
    {Kind::kInstanceOfDestroyed, "instance-of-destroyed", "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-06707", 2,
     1, true},
};
constexpr size_t kKindCount = sizeof(kKinds) / sizeof(kKinds[0]);
constexpr size_t kJobs = 32 * kKindCount;  // 448 jobs: 1088 acceleration-structure commands, 512 submissions a run

constexpr VkBuildAccelerationStructureFlagsKHR kCompactable =
    VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR | VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR;
constexpr VkQueryType kCompactedSize = VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR;

Shape Compactable() {
  Shape s;
  s.flags = kCompactable;
  return s;
}

Shape Static() {  // no ALLOW_UPDATE
  Shape s;
  s.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
  return s;
}

Shape TwoGeometries() {
  Shape s;
  s.geometries = 2;
  return s;
}

VkDeviceSize RoundUp(VkDeviceSize value, VkDeviceSize multiple) { return (value + multiple - 1) / multiple * multiple; }

// What the driver asks of a one-triangle bottom-level build (Shape{}), for the faults that undercut it.
struct Needs {
  VkDeviceSize structure = 0;
  VkDeviceSize scratch = 0;
  VkDeviceSize scratch_alignment = 0;
};

Needs DriverNeeds(vkkit::Device& device, const Inputs& inputs) {
  BuildInfo b = MakeBuildInfo(Shape{}, inputs);
  const uint32_t count = 1;
  VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
  device.GetAccelerationStructureBuildSizesKHR(device.handle(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR,
                                               &b.info, &count, &sizes);
  return {sizes.accelerationStructureSize, sizes.buildScratchSize,
          device.as_properties().minAccelerationStructureScratchOffsetAlignment};
}

std::string CommandBufferName(size_t job, const KindInfo& kind, size_t phase) {
  return "job " + std::to_string(job) + " " + kind.name + " phase " + std::to_string(phase);
}

// One job: its objects, created by the thread that records its first command buffer, destroyed by whichever
// thread reclaims it once its work completed (or its submission was skipped). Only one thread at a time holds a
// job, and hands it over through a Channel: its command pool is externally synchronized that way.
class Job {
 public:
  Job(vkkit::Device& device, const Inputs& inputs, const Needs& needs, size_t index)
      : device_(device), needs_(needs), index_(index), kind_(kKinds[index % kKindCount]),
        commands_(device) {
    VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    vkkit::Check(vkCreateFence(device.handle(), &fence_info, nullptr, &fence_), "vkCreateFence");
    a_ = std::make_unique<Blas>(device, inputs);
    switch (kind_.kind) {
      case Kind::kUpdateIntoOther:
      case Kind::kCloneThenUpdate:
      case Kind::kUpdateChangesGeometryCount:
      case Kind::kInstanceOfDestroyed:
        b_ = std::make_unique<Blas>(device, inputs);
        break;
      case Kind::kCloneOntoAlias:
      case Kind::kCompactOntoAlias:
        b_ = std::make_unique<Blas>(device, inputs, a_.get(), 0);  // the same bytes as a_
        break;
      case Kind::kTopLevel:
        b_ = std::make_unique<Blas>(device, inputs);
        tlas_ = std::make_unique<Tlas>(device);
        instances_ = tlas_->MakeInstances({a_.get(), b_.get()});
        break;
      case Kind::kCompact:
      case Kind::kQueryPastPool:
        queries_ = std::make_unique<QueryPool>(device, kCompactedSize, 1);
        break;
      case Kind::kScratchTooSmall:
        small_scratch_ = device.CreateBuffer(needs.scratch / 2, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
        break;
      case Kind::kDestinationTooSmall:
        small_destination_ = device.CreateAccelerationStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
                                                                needs.structure / 2);
        break;
      default:
        break;
    }
    if (kind_.kind == Kind::kInstanceOfDestroyed) {
      tlas_ = std::make_unique<Tlas>(device);
      instances_ = tlas_->MakeInstances({a_.get(), b_.get()});  // b_ is destroyed before the top-level build
    }
  }

  ~Job() {
    // Aliases before the structure whose storage they share.
    b_.reset();
    a_.reset();
    tlas_.reset();
    queries_.reset();
    if (instances_.buffer) device_.Destroy(instances_);
    if (small_scratch_.buffer) device_.Destroy(small_scratch_);
    if (small_destination_.handle) device_.Destroy(small_destination_);
    if (compacted_.handle) device_.Destroy(compacted_);
    vkDestroyFence(device_.handle(), fence_, nullptr);
  }

  Job(const Job&) = delete;
  Job& operator=(const Job&) = delete;

  size_t index() const { return index_; }
  const KindInfo& kind() const { return kind_; }
  VkFence fence() const { return fence_; }

  // A fresh command buffer of the job's own pool, named after the job and phase, recorded and ended.
  VkCommandBuffer Record(size_t phase) {
    VkCommandBuffer cb = commands_.Begin();
    const std::string name = CommandBufferName(index_, kind_, phase);
    device_.SetName(VK_OBJECT_TYPE_COMMAND_BUFFER, reinterpret_cast<uint64_t>(cb), name.c_str());
    RecordPhase(phase, cb);
    commands_.End(cb);
    return cb;
  }

  // A fault found at submission makes the layer skip the submission (the monitor returns VK_TRUE).
  VkResult ExpectedSubmitResult(size_t phase) const {
    const bool skipped = (kind_.kind == Kind::kUpdateWithoutAllowUpdate ||
                          kind_.kind == Kind::kUpdateChangesGeometryCount) &&
                         phase == kind_.fault_phase;
    return skipped ? VK_ERROR_VALIDATION_FAILED_EXT : VK_SUCCESS;
  }

  // After a phase's work completed, before the next phase is recorded.
  void Completed(size_t phase) {
    if (kind_.kind == Kind::kCompact && phase == 0) {
      const uint64_t compacted_size = queries_->Results(0, 1)[0];
      if (compacted_size == 0) throw std::runtime_error("the compacted-size query returned 0");
      compacted_ = device_.CreateAccelerationStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
                                                       RoundUp(compacted_size, 256));
    }
    if (kind_.kind == Kind::kInstanceOfDestroyed && phase == 0) b_->DestroyHandle();  // its storage stays
  }

 private:
  void RecordPhase(size_t phase, VkCommandBuffer cb) {
    switch (kind_.kind) {
      case Kind::kBuildThenUpdateInPlace:
        a_->Build(cb, Shape{});
        commands_.Barrier(cb);
        a_->Update(cb, Shape{});
        break;
      case Kind::kUpdateIntoOther:
        a_->Build(cb, Shape{});
        commands_.Barrier(cb);
        b_->Update(cb, Shape{}, a_.get());
        break;
      case Kind::kCloneThenUpdate:
        a_->Build(cb, Shape{});
        commands_.Barrier(cb);
        CmdCopy(device_, cb, a_->handle(), b_->handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR);
        commands_.Barrier(cb);
        b_->Update(cb, Shape{});
        break;
      case Kind::kCompact:
        if (phase == 0) {
          queries_->Reset(cb);
          a_->Build(cb, Compactable());
          commands_.Barrier(cb);
          CmdWriteProperties(device_, cb, {a_->handle()}, kCompactedSize, queries_->handle(), 0);
        } else {
          CmdCopy(device_, cb, a_->handle(), compacted_.handle, VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR);
        }
        break;
      case Kind::kTopLevel:
        a_->Build(cb, Shape{});
        b_->Build(cb, Shape{});
        commands_.Barrier(cb);
        tlas_->Record(cb, instances_, 2, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
        commands_.Barrier(cb);
        tlas_->Record(cb, instances_, 2, VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR);
        break;
      case Kind::kUpdateWithoutAllowUpdate:
        a_->Build(cb, Static());
        commands_.Barrier(cb);
        a_->Update(cb, Static());
        break;
      case Kind::kUpdateChangesGeometryCount:
        a_->Build(cb, Shape{});
        commands_.Barrier(cb);
        b_->Update(cb, TwoGeometries(), a_.get());
        break;
      case Kind::kScratchTooSmall: {
        BuildInfo bad = a_->Info(Shape{});
        bad.info.scratchData.deviceAddress = small_scratch_.address;
        RecordBuilds(device_, cb, {&bad});
        a_->Build(cb, Shape{});
        break;
      }
      case Kind::kScratchMisaligned: {
        BuildInfo bad = a_->Info(Shape{});
        bad.info.scratchData.deviceAddress += needs_.scratch_alignment / 2;
        RecordBuilds(device_, cb, {&bad});
        a_->Build(cb, Shape{});
        break;
      }
      case Kind::kDestinationTooSmall: {
        BuildInfo bad = a_->Info(Shape{});
        bad.info.dstAccelerationStructure = small_destination_.handle;
        RecordBuilds(device_, cb, {&bad});
        a_->Build(cb, Shape{});
        break;
      }
      case Kind::kCloneOntoAlias:
        a_->Build(cb, Shape{});
        commands_.Barrier(cb);
        CmdCopy(device_, cb, a_->handle(), b_->handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR);
        break;
      case Kind::kCompactOntoAlias:
        a_->Build(cb, Compactable());
        commands_.Barrier(cb);
        CmdCopy(device_, cb, a_->handle(), b_->handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR);
        break;
      case Kind::kQueryPastPool:
        queries_->Reset(cb);
        a_->Build(cb, Compactable());
        commands_.Barrier(cb);
        CmdWriteProperties(device_, cb, {a_->handle()}, kCompactedSize, queries_->handle(), 0);
        CmdWriteProperties(device_, cb, {a_->handle()}, kCompactedSize, queries_->handle(), 1);  // one past the pool
        break;
      case Kind::kInstanceOfDestroyed:
        if (phase == 0) {
          a_->Build(cb, Shape{});
          b_->Build(cb, Shape{});
        } else {
          tlas_->Record(cb, instances_, 2, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
        }
        break;
    }
  }

  vkkit::Device& device_;
  const Needs needs_;
  const size_t index_;
  const KindInfo& kind_;
  Commands commands_;
  VkFence fence_ = VK_NULL_HANDLE;
  std::unique_ptr<Blas> a_, b_;
  std::unique_ptr<Tlas> tlas_;
  vkkit::Buffer instances_;
  std::unique_ptr<QueryPool> queries_;
  vkkit::Buffer small_scratch_;
  vkkit::AccelerationStructure small_destination_;
  vkkit::AccelerationStructure compacted_;
};

// Problems the threads met (an unexpected VkResult, an exception), gathered for the test's report.
class Problems {
 public:
  void Add(const std::string& what) {
    std::lock_guard<std::mutex> lock(mutex_);
    list_.push_back(what);
  }
  std::vector<std::string> Take() {
    std::lock_guard<std::mutex> lock(mutex_);
    return std::move(list_);
  }

 private:
  std::mutex mutex_;
  std::vector<std::string> list_;
};

// The app's side of the one queue: submissions under its lock (vkQueueSubmit needs the queue externally
// synchronized), waits on the submission's fence outside it.
class Queue {
 public:
  explicit Queue(vkkit::Device& device) : device_(device) {}
  VkResult SubmitAndWait(VkCommandBuffer cb, VkFence fence) {
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cb;
    VkResult result;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      result = vkQueueSubmit(device_.queue(), 1, &submit, fence);
    }
    if (result == VK_SUCCESS) {
      vkkit::Check(vkWaitForFences(device_.handle(), 1, &fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
      vkkit::Check(vkResetFences(device_.handle(), 1, &fence), "vkResetFences");
    }
    return result;
  }

 private:
  vkkit::Device& device_;
  std::mutex mutex_;
};

// The layer reports what it judges on executed bytes when the submission completed, and before the app's wait
// for it returns (capture_tracker.h): then the app may destroy what the finding names. A messenger of the test's
// own keeps the names of the command buffers that errors named so far, for Execute to look up right after a wait.
class Arrivals {
 public:
  explicit Arrivals(vkkit::Instance& instance) : instance_(instance.handle()) {
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
    VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
    info.pfnUserCallback = &Arrivals::Callback;
    info.pUserData = this;
    vkkit::Check(create(instance_, &info, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
  }
  ~Arrivals() {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    destroy(instance_, messenger_, nullptr);
  }
  Arrivals(const Arrivals&) = delete;
  Arrivals& operator=(const Arrivals&) = delete;

  void Clear() {
    std::lock_guard<std::mutex> lock(mutex_);
    names_.clear();
  }
  bool Arrived(const std::string& command_buffer_name) {
    std::lock_guard<std::mutex> lock(mutex_);
    return std::find(names_.begin(), names_.end(), command_buffer_name) != names_.end();
  }

 private:
  static VKAPI_ATTR VkBool32 VKAPI_CALL Callback(VkDebugUtilsMessageSeverityFlagBitsEXT,
                                                 VkDebugUtilsMessageTypeFlagsEXT,
                                                 const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    auto* self = static_cast<Arrivals*>(user);
    std::lock_guard<std::mutex> lock(self->mutex_);
    for (uint32_t i = 0; i < data->objectCount; ++i) {
      const VkDebugUtilsObjectNameInfoEXT& o = data->pObjects[i];
      if (o.objectType == VK_OBJECT_TYPE_COMMAND_BUFFER && o.pObjectName) self->names_.emplace_back(o.pObjectName);
    }
    return VK_FALSE;  // the Monitor decides what the layer skips
  }

  VkInstance instance_;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  std::mutex mutex_;
  std::vector<std::string> names_;
};

// Runs a recorded job's phases: phase 0 was recorded by the thread that made the job; later phases are recorded
// here, after the one before completed.
void Execute(Job& job, VkCommandBuffer first, Queue& queue, Arrivals& arrivals, Problems& problems) {
  VkCommandBuffer cb = first;
  for (size_t phase = 0; phase < job.kind().phases; ++phase) {
    if (phase > 0) cb = job.Record(phase);
    const VkResult result = queue.SubmitAndWait(cb, job.fence());
    if (result != job.ExpectedSubmitResult(phase)) {
      problems.Add(CommandBufferName(job.index(), job.kind(), phase) + ": vkQueueSubmit returned " +
                   std::to_string(result));
      return;
    }
    const KindInfo& kind = job.kind();
    if (kind.at_completion && phase == kind.fault_phase &&
        !arrivals.Arrived(CommandBufferName(job.index(), kind, phase))) {
      problems.Add(CommandBufferName(job.index(), kind, phase) + ": " + kind.vuid +
                   " had not been reported when vkWaitForFences returned");
    }
    job.Completed(phase);
  }
}

// Objects no job uses, made and destroyed while the jobs run: a structure on memory of its own (its address
// asked, never built) and a plain buffer.
void Churn(vkkit::Device& device) {
  vkkit::AccelerationStructure structure =
      device.CreateAccelerationStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, 4096);
  VkAccelerationStructureDeviceAddressInfoKHR address{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR};
  address.accelerationStructure = structure.handle;
  if (device.GetAccelerationStructureDeviceAddressKHR(device.handle(), &address) == 0) {
    throw std::runtime_error("a structure without a device address");
  }
  vkkit::Buffer plain = device.CreateBuffer(1024, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  device.Destroy(plain);
  device.Destroy(structure);
}

// A queue of jobs between two groups of threads; closed by the last producer.
template <typename T>
class Channel {
 public:
  explicit Channel(int producers) : producers_(producers) {}
  void Push(T item) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      items_.push_back(std::move(item));
    }
    ready_.notify_one();
  }
  void ProducerDone() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      --producers_;
    }
    ready_.notify_all();
  }
  // Waits for an item; false once every producer is done and nothing is left.
  bool Pop(T& item) {
    std::unique_lock<std::mutex> lock(mutex_);
    ready_.wait(lock, [&] { return !items_.empty() || producers_ == 0; });
    return Take(item);
  }
  // An item if one is there now. `drained`: every producer is done and nothing is left.
  bool TryPop(T& item, bool& drained) {
    std::lock_guard<std::mutex> lock(mutex_);
    drained = items_.empty() && producers_ == 0;
    return Take(item);
  }

 private:
  bool Take(T& item) {
    if (items_.empty()) return false;
    item = std::move(items_.front());
    items_.pop_front();
    return true;
  }
  std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<T> items_;
  int producers_;
};

struct Recorded {
  std::unique_ptr<Job> job;
  VkCommandBuffer first = VK_NULL_HANDLE;
};

// Every job in order on the calling thread, one churn cycle after each.
void RunOnOneThread(vkkit::Device& device, const Inputs& inputs, const Needs& needs, Arrivals& arrivals,
                    Problems& problems) {
  Queue queue(device);
  for (size_t i = 0; i < kJobs; ++i) {
    try {
      Job job(device, inputs, needs, i);
      Execute(job, job.Record(0), queue, arrivals, problems);
      Churn(device);
    } catch (const std::exception& e) {
      problems.Add("job " + std::to_string(i) + ": " + e.what());
    }
  }
}

constexpr int kRecorders = 4;
constexpr int kSubmitters = 2;
constexpr int kReclaimers = 2;

// The same jobs on recording, submitting and reclaiming threads at once. Returns the churn cycles run.
int RunOnThreads(vkkit::Device& device, const Inputs& inputs, const Needs& needs, Arrivals& arrivals,
                 Problems& problems) {
  Queue queue(device);
  Channel<Recorded> recorded(kRecorders);
  Channel<std::unique_ptr<Job>> finished(kSubmitters);
  std::atomic<size_t> next{0};
  std::atomic<int> churned{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < kRecorders; ++t) {
    threads.emplace_back([&] {
      for (size_t i = next++; i < kJobs; i = next++) {
        try {
          Recorded r;
          r.job = std::make_unique<Job>(device, inputs, needs, i);
          r.first = r.job->Record(0);
          recorded.Push(std::move(r));
        } catch (const std::exception& e) {
          problems.Add("recording job " + std::to_string(i) + ": " + e.what());
        }
      }
      recorded.ProducerDone();
    });
  }
  for (int t = 0; t < kSubmitters; ++t) {
    threads.emplace_back([&] {
      Recorded r;
      while (recorded.Pop(r)) {
        try {
          Execute(*r.job, r.first, queue, arrivals, problems);
        } catch (const std::exception& e) {
          problems.Add("executing job " + std::to_string(r.job->index()) + ": " + e.what());
        }
        finished.Push(std::move(r.job));
      }
      finished.ProducerDone();
    });
  }
  for (int t = 0; t < kReclaimers; ++t) {
    threads.emplace_back([&] {
      try {
        for (;;) {
          std::unique_ptr<Job> done;
          bool drained = false;
          if (finished.TryPop(done, drained)) {
            done.reset();  // its structures, buffers, memory, query pool, fence and command pool
          } else if (drained) {
            break;
          }
          Churn(device);
          ++churned;
        }
      } catch (const std::exception& e) {
        problems.Add(std::string("reclaiming: ") + e.what());
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  return churned;
}

// Findings as "VUID in <name of the command buffer the finding names>", counted. The command buffer is named
// by the job that allocated it just before recording, so its name cannot be a stale one of an earlier object.
std::map<std::string, int> Tally(const std::vector<Message>& messages) {
  std::map<std::string, int> tally;
  for (const Message& m : messages) {
    std::string where;
    for (size_t i = 0; i < m.objects.size(); ++i) {
      if (m.objects[i].objectType == VK_OBJECT_TYPE_COMMAND_BUFFER && !m.names[i].empty()) where = m.names[i];
    }
    ++tally[m.id_name + " in " + (where.empty() ? "no named command buffer: " + m.text : where)];
  }
  return tally;
}

std::vector<std::string> Lines(const std::map<std::string, int>& tally) {
  std::vector<std::string> lines;
  for (const auto& [key, count] : tally) lines.push_back(std::to_string(count) + " x " + key);
  return lines;
}

// What the job list must produce, from the table of faults alone.
std::map<std::string, int> ExpectedFindings() {
  std::map<std::string, int> tally;
  for (size_t i = 0; i < kJobs; ++i) {
    const KindInfo& kind = kKinds[i % kKindCount];
    if (kind.vuid) ++tally[std::string(kind.vuid) + " in " + CommandBufferName(i, kind, kind.fault_phase)];
  }
  return tally;
}

void ExpectFaults(Monitor& monitor) {
  for (const KindInfo& kind : kKinds) {
    if (kind.vuid) monitor.Expect(kind.vuid);  // the callback then returns VK_TRUE: the layer skips the call
  }
}

TEST_CASE("stress: jobs recorded, submitted, waited for and destroyed on threads report what one thread does",
          "[integration][threads][stress]") {
  HistoryFixture f(nullptr, {{"duplicate_message_limit", "0"}});  // unlimited: every job's finding must arrive
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  const Needs needs = DriverNeeds(device, inputs);
  REQUIRE(needs.scratch >= 2);  // halved for scratch-too-small
  REQUIRE(needs.structure >= 2);  // halved for destination-too-small
  REQUIRE(needs.scratch_alignment >= 2);  // half of it misaligns the scratch
  const std::vector<std::string> expected = Lines(ExpectedFindings());

  Arrivals arrivals(f.instance());
  Problems problems;
  ExpectFaults(f.monitor());
  RunOnOneThread(device, inputs, needs, arrivals, problems);
  const std::vector<std::string> one_thread = Lines(Tally(f.monitor().Take()));
  CHECK(problems.Take() == std::vector<std::string>{});
  CHECK(one_thread == expected);

  ExpectFaults(f.monitor());
  arrivals.Clear();  // the same jobs, the same names
  const int churned = RunOnThreads(device, inputs, needs, arrivals, problems);
  const std::vector<std::string> threaded = Lines(Tally(f.monitor().Take()));
  CHECK(problems.Take() == std::vector<std::string>{});
  CHECK(threaded == one_thread);
  CHECK(churned > 0);
}

}  // namespace
}  // namespace asval_test
