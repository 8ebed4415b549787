// Threads record builds and updates into their own command buffers, submit them to the one queue (under the
// app's lock, as the spec requires), and create and destroy structures, all at once. Under ThreadSanitizer
// this is the history's race detector; in every build, each thread's deliberately mismatched update must be
// reported exactly once and nothing else.
#include <catch2/catch_test_macros.hpp>

#include <atomic>
#include <mutex>
#include <thread>

#include "history_helpers.h"

namespace asval_test {
namespace {

TEST_CASE("history: threads recording, submitting and destroying at once", "[integration][history][threads]") {
  HistoryFixture f(nullptr, {{"duplicate_message_limit", "0"}});
  vkkit::Device& device = f.device();
  constexpr int kThreads = 4;
  constexpr int kRounds = 4;
  // One mismatched update per thread, in its last round; the layer skips that submission.
  f.monitor().Expect("VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03758", kThreads);
  std::mutex queue_mutex;
  std::atomic<int> failures{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&] {
      try {
        Inputs inputs(device);
        Commands commands(device);
        for (int round = 0; round < kRounds; ++round) {
          Blas blas(device, inputs);  // created and destroyed every round, on every thread
          VkCommandBuffer build = commands.Begin();
          blas.Build(build, Shape{});
          commands.End(build);
          Shape update_shape;
          if (round == kRounds - 1) update_shape.geometries = 2;
          VkCommandBuffer update = commands.Begin();
          blas.Update(update, update_shape);
          commands.End(update);
          std::lock_guard<std::mutex> lock(queue_mutex);
          if (commands.Submit(build) != VK_SUCCESS) ++failures;
          const VkResult expected = round == kRounds - 1 ? VK_ERROR_VALIDATION_FAILED_EXT : VK_SUCCESS;
          if (commands.Submit(update) != expected) ++failures;
        }
      } catch (...) {
        ++failures;
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  CHECK(failures == 0);
  CHECK(f.monitor().Verify() == "");
}

}  // namespace
}  // namespace asval_test
