// Aliasing clobbers history: a build (or copy) that writes memory overlapping another structure's memory
// leaves that structure's contents garbage; using it afterwards as an update source or a copy source is
// reported (ASVAL-History-Clobbered, a warning). Destroying a structure ends its history.
#include <catch2/catch_test_macros.hpp>

#include "history_helpers.h"

namespace asval_test {
namespace {

constexpr const char* kClobbered = "ASVAL-History-Clobbered";

void Submit(vkkit::Device& device, const std::function<void(Commands&, VkCommandBuffer)>& record,
            VkResult expected = VK_SUCCESS) {
  Commands commands(device);
  VkCommandBuffer cb = commands.Begin();
  record(commands, cb);
  commands.End(cb);
  CHECK(commands.Submit(cb) == expected);
}

TEST_CASE("history: updating a structure whose memory another build overwrote is reported (ASVAL-History-Clobbered)",
          "[integration][history]") {
  HistoryFixture f("history");
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas a(device, inputs);
  Blas b(device, inputs, &a);  // the same bytes of the same buffer
  Submit(device, [&](Commands&, VkCommandBuffer cb) { a.Build(cb, Shape{}); });
  Submit(device, [&](Commands&, VkCommandBuffer cb) { b.Build(cb, Shape{}); });
  f.monitor().Expect(kClobbered);
  Submit(device, [&](Commands&, VkCommandBuffer cb) { a.Update(cb, Shape{}); }, VK_ERROR_VALIDATION_FAILED_EXT);
  std::vector<Message> messages = f.monitor().Take();
  REQUIRE(messages.size() == 1);
  CHECK(messages[0].severity == VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT);
  CHECK(messages[0].text.find("after its memory was overwritten") != std::string::npos);
  // A copy from it is reported the same way.
  Blas c(device, inputs);
  f.monitor().Expect(kClobbered);
  Submit(device, [&](Commands&, VkCommandBuffer cb) {
    CmdCopy(device, cb, a.handle(), c.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR);
  }, VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("history valid twin: separate memory, or a rebuild after the overwrite, stays silent "
          "(ASVAL-History-Clobbered)",
          "[integration][history]") {
  HistoryFixture f;
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas a(device, inputs), separate(device, inputs);
  Submit(device, [&](Commands& commands, VkCommandBuffer cb) {
    a.Build(cb, Shape{});
    separate.Build(cb, Shape{});
    commands.Barrier(cb);
    a.Update(cb, Shape{});
  });
  Blas alias(device, inputs, &a);
  Submit(device, [&](Commands&, VkCommandBuffer cb) { alias.Build(cb, Shape{}); });  // overwrites a
  Submit(device, [&](Commands& commands, VkCommandBuffer cb) {
    a.Build(cb, Shape{});  // rebuilt: its contents are what was built again (and alias's are not)
    commands.Barrier(cb);
    a.Update(cb, Shape{});
  });
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("history: destroying a structure ends its history; one created in its place starts unbuilt (src-04963)",
          "[integration][history][passes-invalid-down]") {
  HistoryFixture f("history");
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs), dst(device, inputs);
  Submit(device, [&](Commands&, VkCommandBuffer cb) { blas.Build(cb, Shape{}); });
  blas.Recreate();  // destroyed, and a new structure over the same memory (often with the same handle value)
  f.monitor().Expect("VUID-VkCopyAccelerationStructureInfoKHR-src-04963");
  Submit(device, [&](Commands&, VkCommandBuffer cb) {
    CmdCopy(device, cb, blas.handle(), dst.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR);
  }, VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(f.monitor().Verify() == "");
}

}  // namespace
}  // namespace asval_test
