// Many threads create, bind, build with and destroy objects at once, as engines recording command buffers
// on worker threads do. Run under ThreadSanitizer (the tsan preset) this is the layer's race detector;
// in every build it checks that each thread's findings arrive, no more and no fewer.
#include <catch2/catch_test_macros.hpp>
#include <atomic>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "fixture.h"
#include "history_helpers.h"

namespace asval_test {
namespace {

TEST_CASE("concurrent recording on several threads", "[integration][threads]") {
  ApiSettings settings;
  settings.Add("duplicate_message_limit", "0");  // unlimited: every thread's findings must arrive
  Fixture f(settings.Chain());
  vkkit::Device& device = f.device();
  const uint32_t alignment = device.as_properties().minAccelerationStructureScratchOffsetAlignment;
  constexpr int kThreads = 4;
  constexpr int kRounds = 6;
  f.monitor().Expect("VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710", kThreads * kRounds);

  std::atomic<int> failures{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      try {
        VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
        VkCommandPool pool = VK_NULL_HANDLE;
        vkkit::Check(vkCreateCommandPool(device.handle(), &pool_info, nullptr, &pool), "pool");
        for (int round = 0; round < kRounds; ++round) {
          vkkit::TriangleBuild build(device);
          VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
          alloc.commandPool = pool;
          alloc.commandBufferCount = 1;
          VkCommandBuffer cb = VK_NULL_HANDLE;
          vkkit::Check(vkAllocateCommandBuffers(device.handle(), &alloc, &cb), "cb");
          VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
          vkkit::Check(vkBeginCommandBuffer(cb, &begin), "begin");
          build.UseScratchOffset((t + round) % 2 ? alignment : 0);  // valid either way
          build.Record(device, cb);
          build.UseScratchOffset(alignment / 2);  // invalid: reported, skipped by the monitor
          build.Record(device, cb);
          vkkit::Check(vkEndCommandBuffer(cb), "end");
          vkFreeCommandBuffers(device.handle(), pool, 1, &cb);
          build.Release(device);
        }
        vkDestroyCommandPool(device.handle(), pool, nullptr);
      } catch (...) {
        ++failures;
      }
    });
  }
  for (std::thread& th : threads) th.join();
  CHECK(failures == 0);
  CHECK(f.monitor().Verify() == "");
}


TEST_CASE("threads submitting builds and destroying their inputs once their own fences signaled, while the others' "
          "work is in flight, stay silent (lifetime)",
          "[integration][threads][lifetime]") {
  HistoryFixture f;
  vkkit::Device& device = f.device();
  constexpr int kThreads = 4;
  constexpr int kRounds = 5;
  std::mutex queue_mutex;  // the queue is externally synchronized
  std::atomic<int> failures{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&] {
      try {
        Commands commands(device);
        VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
        VkFence fence = VK_NULL_HANDLE;
        vkkit::Check(vkCreateFence(device.handle(), &fence_info, nullptr, &fence), "fence");
        for (int round = 0; round < kRounds; ++round) {
          auto inputs = std::make_unique<Inputs>(device);
          auto blas = std::make_unique<Blas>(device, *inputs);
          const VkCommandBuffer cb = commands.Begin();
          blas->Build(cb, Shape{});
          commands.End(cb);
          VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
          submit.commandBufferCount = 1;
          submit.pCommandBuffers = &cb;
          {
            std::lock_guard<std::mutex> lock(queue_mutex);
            vkkit::Check(vkQueueSubmit(device.queue(), 1, &submit, fence), "submit");
          }
          vkkit::Check(vkWaitForFences(device.handle(), 1, &fence, VK_TRUE, 10ull * 1000 * 1000 * 1000), "wait");
          vkkit::Check(vkResetFences(device.handle(), 1, &fence), "reset");
          blas.reset();  // its work completed: the structure, its buffers and the inputs go
          inputs.reset();
        }
        vkDestroyFence(device.handle(), fence, nullptr);
      } catch (...) {
        ++failures;
      }
    });
  }
  for (std::thread& th : threads) th.join();
  CHECK(failures == 0);
  CHECK(f.monitor().Verify() == "");
}

}  // namespace
}  // namespace asval_test
