// Family traces (issue 29): trace and ray-query work reads top-level structures that a build has executed on, in
// execution order. The firing cases are skipped by the monitor's VK_TRUE, so no invalid work reaches lavapipe; the
// valid twins run on it, are waited for, and must compute the ray's hit (the layer changes nothing the app computes).
#include <catch2/catch_test_macros.hpp>
#include <cstring>
#include <memory>

#include "history_helpers.h"
#include "ray_query.comp.h"
#include "trace_miss.rmiss.h"
#include "trace_ray.rgen.h"

namespace asval_test {
namespace {

constexpr const char kRayQueryBuilt[] = "VUID-RuntimeSpirv-OpRayQueryInitializeKHR-06352";
constexpr const char kTraceRayBuilt[] = "VUID-RuntimeSpirv-OpTraceRayKHR-06359";

void Check(VkResult result) { REQUIRE(result == VK_SUCCESS); }

// A device with ray-tracing pipelines and push descriptors besides what every test device has (ray queries on
// lavapipe).
vkkit::DeviceOptions RayDevice() {
  static VkPhysicalDeviceRayTracingPipelineFeaturesKHR pipelines{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR};
  pipelines.rayTracingPipeline = VK_TRUE;
  vkkit::DeviceOptions options;
  options.extensions = {VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME, VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME};
  options.features = &pipelines;
  return options;
}

VkShaderModule MakeModule(VkDevice device, const uint32_t* code, std::size_t bytes) {
  VkShaderModuleCreateInfo info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  info.codeSize = bytes;
  info.pCode = code;
  VkShaderModule module = VK_NULL_HANDLE;
  Check(vkCreateShaderModule(device, &info, nullptr, &module));
  return module;
}

// A pipeline reading a top-level structure at set 0, binding 0 and writing whether its ray hit into a storage buffer
// at binding 1: a compute pipeline with a ray query (ray_query.comp) or a ray-tracing pipeline (trace_ray.rgen and
// trace_miss.rmiss, with its shader binding table). `push`: the set layout is for push descriptors (no set).
class RayProgram {
 public:
  enum class Kind { kRayQuery, kTraceRays };
  RayProgram(vkkit::Device& device, Kind kind, bool push = false) : device_(device), kind_(kind) {
    const VkDevice d = device.handle();
    const VkShaderStageFlags stage =
        kind == Kind::kRayQuery ? VK_SHADER_STAGE_COMPUTE_BIT : VK_SHADER_STAGE_RAYGEN_BIT_KHR;
    VkDescriptorSetLayoutBinding bindings[2] = {{0, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1, stage, nullptr},
                                                {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, stage, nullptr}};
    VkDescriptorSetLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    layout_info.flags = push ? VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR : 0;
    layout_info.bindingCount = 2;
    layout_info.pBindings = bindings;
    Check(vkCreateDescriptorSetLayout(d, &layout_info, nullptr, &set_layout_));
    VkPipelineLayoutCreateInfo pipeline_layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    pipeline_layout_info.setLayoutCount = 1;
    pipeline_layout_info.pSetLayouts = &set_layout_;
    Check(vkCreatePipelineLayout(d, &pipeline_layout_info, nullptr, &layout_));
    output_ = device.CreateBuffer(256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    if (kind == Kind::kRayQuery) {
      MakeComputePipeline();
    } else {
      MakeRayTracingPipeline();
    }
    if (!push) {
      VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 4},
                                       {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 4}};
      VkDescriptorPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
      pool_info.maxSets = 2;
      pool_info.poolSizeCount = 2;
      pool_info.pPoolSizes = sizes;
      Check(vkCreateDescriptorPool(d, &pool_info, nullptr, &pool_));
      VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
      alloc.descriptorPool = pool_;
      alloc.descriptorSetCount = 1;
      alloc.pSetLayouts = &set_layout_;
      Check(vkAllocateDescriptorSets(d, &alloc, &set_));
    }
  }
  ~RayProgram() {
    const VkDevice d = device_.handle();
    if (pool_) vkDestroyDescriptorPool(d, pool_, nullptr);
    vkDestroyPipeline(d, pipeline_, nullptr);
    vkDestroyPipelineLayout(d, layout_, nullptr);
    vkDestroyDescriptorSetLayout(d, set_layout_, nullptr);
    device_.Destroy(output_);
    if (sbt_.buffer) device_.Destroy(sbt_);
  }
  RayProgram(const RayProgram&) = delete;
  RayProgram& operator=(const RayProgram&) = delete;

  VkDescriptorSet set() const { return set_; }
  // Writes `structure` into the set's binding 0 (and the output buffer into binding 1).
  void Write(VkAccelerationStructureKHR structure) {
    Writes w(*this, structure);
    vkUpdateDescriptorSets(device_.handle(), 2, w.writes, 0, nullptr);
  }
  // Binds the pipeline and the set (or pushes `pushed`), and traces or dispatches one ray.
  void Record(VkCommandBuffer cb, VkAccelerationStructureKHR pushed = VK_NULL_HANDLE) {
    const VkPipelineBindPoint point = bind_point();
    vkCmdBindPipeline(cb, point, pipeline_);
    if (set_) {
      vkCmdBindDescriptorSets(cb, point, layout_, 0, 1, &set_, 0, nullptr);
    } else {
      Writes w(*this, pushed);
      auto push = reinterpret_cast<PFN_vkCmdPushDescriptorSetKHR>(
          vkGetDeviceProcAddr(device_.handle(), "vkCmdPushDescriptorSetKHR"));
      push(cb, point, layout_, 0, 2, w.writes);
    }
    if (kind_ == Kind::kRayQuery) {
      vkCmdDispatch(cb, 1, 1, 1);
      return;
    }
    auto trace = reinterpret_cast<PFN_vkCmdTraceRaysKHR>(vkGetDeviceProcAddr(device_.handle(), "vkCmdTraceRaysKHR"));
    const VkStridedDeviceAddressRegionKHR none{};
    trace(cb, &raygen_, &miss_, &none, &none, 1, 1, 1);
  }
  // Build writes made visible to the ray's reads.
  void BarrierAfterBuild(VkCommandBuffer cb) const {
    VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;
    barrier.dstAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR;
    const VkPipelineStageFlags stage =
        kind_ == Kind::kRayQuery ? VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT : VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, stage, 0, 1, &barrier, 0, nullptr,
                         0, nullptr);
  }
  // What the last ray wrote (1: it hit); cleared to 7 by Clear().
  uint32_t hit() const { return *static_cast<const uint32_t*>(output_.mapped); }
  void Clear() { *static_cast<uint32_t*>(output_.mapped) = 7; }

 private:
  struct Writes {
    Writes(const RayProgram& p, VkAccelerationStructureKHR structure) : as(structure) {
      as_info.accelerationStructureCount = 1;
      as_info.pAccelerationStructures = &as;
      buffer_info = {p.output_.buffer, 0, VK_WHOLE_SIZE};
      writes[0] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,        &as_info, p.set_,  0,      0, 1,
                   VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, nullptr,  nullptr, nullptr};
      writes[1] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, nullptr, p.set_,       1,      0, 1,
                   VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,      nullptr, &buffer_info, nullptr};
    }
    Writes(const Writes&) = delete;
    VkAccelerationStructureKHR as;
    VkWriteDescriptorSetAccelerationStructureKHR as_info{
        VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
    VkDescriptorBufferInfo buffer_info{};
    VkWriteDescriptorSet writes[2];
  };

  VkPipelineBindPoint bind_point() const {
    return kind_ == Kind::kRayQuery ? VK_PIPELINE_BIND_POINT_COMPUTE : VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR;
  }

  void MakeComputePipeline() {
    const VkShaderModule module = MakeModule(device_.handle(), kRayQueryComp, sizeof(kRayQueryComp));
    VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    info.stage.module = module;
    info.stage.pName = "main";
    info.layout = layout_;
    Check(vkCreateComputePipelines(device_.handle(), VK_NULL_HANDLE, 1, &info, nullptr, &pipeline_));
    vkDestroyShaderModule(device_.handle(), module, nullptr);  // the pipeline keeps what it needs
  }

  void MakeRayTracingPipeline() {
    const VkDevice d = device_.handle();
    const VkShaderModule raygen = MakeModule(d, kTraceRayRgen, sizeof(kTraceRayRgen));
    const VkShaderModule miss = MakeModule(d, kTraceMissRmiss, sizeof(kTraceMissRmiss));
    VkPipelineShaderStageCreateInfo stages[2] = {{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO},
                                                 {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO}};
    stages[0].stage = VK_SHADER_STAGE_RAYGEN_BIT_KHR;
    stages[0].module = raygen;
    stages[0].pName = "main";
    stages[1].stage = VK_SHADER_STAGE_MISS_BIT_KHR;
    stages[1].module = miss;
    stages[1].pName = "main";
    VkRayTracingShaderGroupCreateInfoKHR groups[2] = {{VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_KHR},
                                                      {VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_KHR}};
    for (uint32_t i = 0; i < 2; ++i) {
      groups[i].type = VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR;
      groups[i].generalShader = i;
      groups[i].closestHitShader = groups[i].anyHitShader = groups[i].intersectionShader = VK_SHADER_UNUSED_KHR;
    }
    VkRayTracingPipelineCreateInfoKHR info{VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR};
    info.stageCount = 2;
    info.pStages = stages;
    info.groupCount = 2;
    info.pGroups = groups;
    info.maxPipelineRayRecursionDepth = 1;
    info.layout = layout_;
    auto create =
        reinterpret_cast<PFN_vkCreateRayTracingPipelinesKHR>(vkGetDeviceProcAddr(d, "vkCreateRayTracingPipelinesKHR"));
    Check(create(d, VK_NULL_HANDLE, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline_));
    vkDestroyShaderModule(d, raygen, nullptr);
    vkDestroyShaderModule(d, miss, nullptr);

    // The shader binding table: the raygen and miss handles, each at a base-aligned offset.
    VkPhysicalDeviceRayTracingPipelinePropertiesKHR rt{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_PROPERTIES_KHR};
    VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &rt};
    vkGetPhysicalDeviceProperties2(device_.physical_device(), &props);
    const uint32_t handle_size = rt.shaderGroupHandleSize;
    const VkDeviceSize stride =
        (handle_size + rt.shaderGroupBaseAlignment - 1) / rt.shaderGroupBaseAlignment * rt.shaderGroupBaseAlignment;
    std::vector<uint8_t> handles(2 * handle_size);
    auto get = reinterpret_cast<PFN_vkGetRayTracingShaderGroupHandlesKHR>(
        vkGetDeviceProcAddr(d, "vkGetRayTracingShaderGroupHandlesKHR"));
    Check(get(d, pipeline_, 0, 2, handles.size(), handles.data()));
    sbt_ = device_.CreateBuffer(2 * stride + rt.shaderGroupBaseAlignment, VK_BUFFER_USAGE_SHADER_BINDING_TABLE_BIT_KHR);
    const VkDeviceAddress base =
        (sbt_.address + rt.shaderGroupBaseAlignment - 1) / rt.shaderGroupBaseAlignment * rt.shaderGroupBaseAlignment;
    auto* bytes = static_cast<uint8_t*>(sbt_.mapped) + (base - sbt_.address);
    std::memcpy(bytes, handles.data(), handle_size);
    std::memcpy(bytes + stride, handles.data() + handle_size, handle_size);
    raygen_ = {base, stride, stride};
    miss_ = {base + stride, stride, stride};
  }

  vkkit::Device& device_;
  Kind kind_;
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  VkDescriptorSet set_ = VK_NULL_HANDLE;
  vkkit::Buffer output_;
  vkkit::Buffer sbt_;
  VkStridedDeviceAddressRegionKHR raygen_{}, miss_{};
};

// A bottom-level structure of one triangle under (0.25, 0.25) and a top-level structure with one instance of it.
struct Scene {
  explicit Scene(vkkit::Device& d)
      : device(d), inputs(d), blas(d, inputs), tlas(d), instances(tlas.MakeInstances({&blas})) {}
  ~Scene() { device.Destroy(instances); }
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;
  // Both builds, with the barrier between them.
  void Build(Commands& commands, VkCommandBuffer cb) {
    blas.Build(cb, Shape{});
    commands.Barrier(cb);
    tlas.Record(cb, instances, 1, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
  }

  vkkit::Device& device;
  Inputs inputs;
  Blas blas;
  Tlas tlas;
  vkkit::Buffer instances;
};

TEST_CASE(
    "traces: a ray query dispatched over a top-level structure no build executed on (OpRayQueryInitializeKHR-06352)",
    "[integration][traces]") {
  HistoryFixture f("traces", {}, RayDevice());
  vkkit::Device& device = f.device();
  Tlas never_built(device);
  RayProgram program(device, RayProgram::Kind::kRayQuery);
  program.Write(never_built.handle());
  Commands commands(device);
  const VkCommandBuffer cb = Recorded(commands, [&](VkCommandBuffer c) { program.Record(c); });
  f.monitor().Expect(kRayQueryBuilt);
  commands.Submit(cb);  // skipped by the monitor's VK_TRUE: the ray never reads the unbuilt structure
  CHECK(f.monitor().Verify() == "");
  // The same structure pushed (vkCmdPushDescriptorSetKHR) rather than bound through a set.
  RayProgram pushing(device, RayProgram::Kind::kRayQuery, true);
  const VkCommandBuffer pushed =
      Recorded(commands, [&](VkCommandBuffer c) { pushing.Record(c, never_built.handle()); });
  f.monitor().Expect(kRayQueryBuilt);
  commands.Submit(pushed);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("traces: a ray-tracing pipeline traces a top-level structure no build executed on (OpTraceRayKHR-06359)",
          "[integration][traces]") {
  HistoryFixture f("traces", {}, RayDevice());
  vkkit::Device& device = f.device();
  Tlas never_built(device);
  RayProgram program(device, RayProgram::Kind::kTraceRays);
  program.Write(never_built.handle());
  Commands commands(device);
  const VkCommandBuffer cb = Recorded(commands, [&](VkCommandBuffer c) { program.Record(c); });
  f.monitor().Expect(kTraceRayBuilt);
  commands.Submit(cb);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE(
    "traces: execution order, not recording order: the build recorded first but submitted after the dispatch "
    "is reported",
    "[integration][traces]") {
  HistoryFixture f("traces", {}, RayDevice());
  vkkit::Device& device = f.device();
  Scene scene(device);
  RayProgram program(device, RayProgram::Kind::kRayQuery);
  program.Write(scene.tlas.handle());
  Commands commands(device);
  const VkCommandBuffer build = Recorded(commands, [&](VkCommandBuffer c) { scene.Build(commands, c); });
  const VkCommandBuffer query = Recorded(commands, [&](VkCommandBuffer c) { program.Record(c); });
  f.monitor().Expect(kRayQueryBuilt);
  commands.Submit(query);  // before the build's submission: skipped
  CHECK(f.monitor().Verify() == "");
  REQUIRE(commands.Submit(build) == VK_SUCCESS);  // waits for the queue
  program.Clear();
  REQUIRE(commands.Submit(query) == VK_SUCCESS);  // the same recording, now after the build: silent
  CHECK(program.hit() == 1u);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("traces valid twin: the trace reads a structure built earlier in execution order", "[integration][traces]") {
  HistoryFixture f(nullptr, {}, RayDevice());
  vkkit::Device& device = f.device();
  Commands commands(device);
  Scene scene(device);
  // Built and queried in one command buffer, the build's writes made visible to the query.
  RayProgram query(device, RayProgram::Kind::kRayQuery);
  query.Write(scene.tlas.handle());
  query.Clear();
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer c) {
    scene.Build(commands, c);
    query.BarrierAfterBuild(c);
    query.Record(c);
  })) == VK_SUCCESS);
  CHECK(query.hit() == 1u);
  // Traced by a ray-tracing pipeline in a later submission.
  RayProgram trace(device, RayProgram::Kind::kTraceRays);
  trace.Write(scene.tlas.handle());
  trace.Clear();
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer c) { trace.Record(c); })) == VK_SUCCESS);
  CHECK(trace.hit() == 1u);
  // Descriptors rewritten before the trace: the set first named a structure never built.
  Tlas never_built(device);
  query.Write(never_built.handle());
  query.Write(scene.tlas.handle());
  query.Clear();
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer c) { query.Record(c); })) == VK_SUCCESS);
  CHECK(query.hit() == 1u);
  // Pushed rather than bound.
  RayProgram pushing(device, RayProgram::Kind::kRayQuery, true);
  pushing.Clear();
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer c) { pushing.Record(c, scene.tlas.handle()); })) ==
          VK_SUCCESS);
  CHECK(pushing.hit() == 1u);
  CHECK(f.monitor().Verify() == "");
}

}  // namespace
}  // namespace asval_test
