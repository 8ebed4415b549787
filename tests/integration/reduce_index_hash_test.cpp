// The layer's reducing dispatch hashes each 64 triangles' index bytes on the device (issue 27: the host then
// combines one hash per block instead of hashing every index). The host compares those hashes with hashes the
// reference builder computed on the CPU (a build captured by copy, or classified on the host, against an update
// reduced on the device), so the shader must compute builder::HashIndexBlock bit for bit, or an unchanged index
// buffer would be reported as changed (pInfos-03768). This test runs the layer's own shader
// (layer/capture/shaders/reduce_inputs.comp) on the device under test, on random index bytes of each index type,
// at addresses aligned only to the index size, with counts that leave every kind of tail, and compares each block's
// hash with the builder's.
#include <catch2/catch_test_macros.hpp>

#include <algorithm>
#include <cstring>
#include <random>
#include <vector>

#include "asval/builder/index_hash.h"
#include "fixture.h"
#include "reduce_inputs.comp.h"

namespace asval_test {
namespace {

// The shader's Job (reduce_inputs.comp), written out here rather than taken from the layer: the test states the
// layout it expects.
struct Job {
  uint32_t kind = 0;  // triangles
  uint32_t count = 0;
  uint32_t stride = 12;
  // x_kind (bits 0-7) 0: no NaN test, the vertices are not read; components (bits 8-15) 3; index_bytes (bits 16-23).
  uint32_t format = 3u << 8;
  uint32_t first_vertex = 0;
  uint32_t max_vertex = 0xffffffffu;  // every index readable
  uint64_t data = 0;
  uint64_t indices = 0;
  uint64_t out = 0;
  uint64_t transform = 0;
  uint64_t range = 0;  // not an indirect build's job
};
static_assert(sizeof(Job) == 64, "the shader's job is 64 bytes");

class ReducePipeline {
 public:
  // The slab table (one address: the job's buffer) is a specialization constant, as the layer passes it.
  ReducePipeline(vkkit::Device& device, VkDeviceAddress table) : device_(device) {
    const VkDevice d = device.handle();
    VkPipelineLayoutCreateInfo layout{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    vkkit::Check(vkCreatePipelineLayout(d, &layout, nullptr, &layout_), "vkCreatePipelineLayout");
    VkShaderModuleCreateInfo module{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    module.codeSize = sizeof(kReduceInputsSpirv);
    module.pCode = kReduceInputsSpirv;
    VkShaderModule shader = VK_NULL_HANDLE;
    vkkit::Check(vkCreateShaderModule(d, &module, nullptr, &shader), "vkCreateShaderModule");
    const uint32_t words[2] = {static_cast<uint32_t>(table), static_cast<uint32_t>(table >> 32)};
    const VkSpecializationMapEntry entries[2] = {{0, 0, 4}, {1, 4, 4}};
    VkSpecializationInfo specialization{2, entries, sizeof(words), words};
    VkComputePipelineCreateInfo pipeline{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    pipeline.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    pipeline.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    pipeline.stage.module = shader;
    pipeline.stage.pName = "main";
    pipeline.stage.pSpecializationInfo = &specialization;
    pipeline.layout = layout_;
    vkkit::Check(vkCreateComputePipelines(d, VK_NULL_HANDLE, 1, &pipeline, nullptr, &pipeline_),
                 "vkCreateComputePipelines");
    vkDestroyShaderModule(d, shader, nullptr);
  }
  ~ReducePipeline() {
    vkDestroyPipeline(device_.handle(), pipeline_, nullptr);
    vkDestroyPipelineLayout(device_.handle(), layout_, nullptr);
  }
  ReducePipeline(const ReducePipeline&) = delete;
  ReducePipeline& operator=(const ReducePipeline&) = delete;

  // `groups` groups of 64 for job 0, then its writes made visible to the host.
  void Run(uint32_t groups) {
    device_.OneShot([&](VkCommandBuffer cb) {
      vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_);
      vkCmdDispatch(cb, groups, 1, 1);
      VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
      barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
      barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
      vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &barrier, 0,
                           nullptr, 0, nullptr);
    });
  }

 private:
  vkkit::Device& device_;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
};

struct Case {
  uint32_t index_bytes;
  uint32_t offset;  // of the first index: a multiple of the index size only
  uint32_t triangles;
  uint32_t groups;  // fewer than the blocks: the shader's grid-stride loop
};

TEST_CASE("reduce index hash: the device's hash of each 64 triangles' indices is the builder's, bit for bit",
          "[integration][capture]") {
  Fixture f;
  vkkit::Device& device = f.device();
  constexpr VkDeviceSize kIndexSpace = 3 * 4 * 700 + 64;
  constexpr VkDeviceSize kOutSpace = 4096;
  vkkit::Buffer indices = device.CreateBuffer(kIndexSpace, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  vkkit::Buffer job = device.CreateBuffer(sizeof(Job), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  vkkit::Buffer table = device.CreateBuffer(sizeof(uint64_t), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  vkkit::Buffer out = device.CreateBuffer(kOutSpace, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  const uint64_t job_address = job.address;
  std::memcpy(table.mapped, &job_address, sizeof(job_address));
  ReducePipeline pipeline(device, table.address);

  std::mt19937 random(27);
  auto* index_bytes_at = static_cast<uint8_t*>(indices.mapped);
  for (VkDeviceSize k = 0; k < kIndexSpace; ++k) index_bytes_at[k] = static_cast<uint8_t>(random());

  // Tails of every length class: a block's 192 * size bytes are whole 32-byte steps; 1, 5, 11 and 43 triangles leave
  // 3 to 129 * size bytes, with and without a partial step, and a step ending in a partial word.
  const Case cases[] = {
      {1, 3, 1, 1},   {1, 1, 11, 1},  {1, 0, 64, 1},  {1, 3, 65, 2},  {1, 1, 300, 2}, {2, 2, 1, 1},
      {2, 6, 5, 1},   {2, 0, 43, 1},  {2, 2, 128, 2}, {2, 4, 700, 3}, {4, 4, 1, 1},   {4, 0, 11, 1},
      {4, 12, 64, 1}, {4, 8, 129, 3}, {4, 4, 700, 4}, {4, 0, 255, 4},
  };
  for (const Case& c : cases) {
    CAPTURE(c.index_bytes, c.offset, c.triangles, c.groups);
    Job j;
    j.count = c.triangles;
    j.format |= c.index_bytes << 16;
    j.indices = indices.address + c.offset;
    j.data = indices.address;  // not read (x_kind 0)
    j.out = out.address;
    std::memcpy(job.mapped, &j, sizeof(j));
    std::memset(out.mapped, 0xa5, kOutSpace);
    pipeline.Run(c.groups);

    // The bit arrays come first (three of one bit per triangle, in words), then one 16-byte hash per block.
    const auto* out_bytes = static_cast<const uint8_t*>(out.mapped);
    const uint32_t words = (c.triangles + 31) / 32;
    const uint8_t* hashes = out_bytes + 3 * 4 * words;
    const uint8_t* first = index_bytes_at + c.offset;
    const size_t total = size_t{3} * c.triangles * c.index_bytes;
    const size_t block = asval::builder::IndexHashBlockBytes(c.index_bytes);
    asval::builder::IndexHashCombiner combined(c.index_bytes);
    for (size_t at = 0, k = 0; at < total; at += block, ++k) {
      CAPTURE(k);
      const asval::builder::Hash128 expected =
          asval::builder::HashIndexBlock(first + at, std::min(block, total - at), c.index_bytes);
      asval::builder::Hash128 device_hash;
      std::memcpy(&device_hash.lo, hashes + 16 * k, 8);
      std::memcpy(&device_hash.hi, hashes + 16 * k + 8, 8);
      CHECK(device_hash.lo == expected.lo);
      CHECK(device_hash.hi == expected.hi);
      combined.Add(device_hash);
    }
    // Combined as the layer combines them: the builder's hash of the whole range.
    const asval::builder::Hash128 whole = asval::builder::HashIndexBytes(first, total, c.index_bytes);
    const asval::builder::Hash128 from_device = combined.Finish(total);
    CHECK(from_device.lo == whole.lo);
    CHECK(from_device.hi == whole.hi);
    // Every triangle active and readable (the bit arrays are the shader's other tests' business: capture_*_test).
    std::vector<uint32_t> bits(3 * words);
    std::memcpy(bits.data(), out_bytes, bits.size() * 4);
    for (uint32_t t = 0; t < c.triangles; ++t) REQUIRE(((bits[t / 32] >> (t % 32)) & 1u) == 1u);
  }
  CHECK(f.monitor().Verify() == "");
  device.Destroy(out);
  device.Destroy(table);
  device.Destroy(job);
  device.Destroy(indices);
}

}  // namespace
}  // namespace asval_test
