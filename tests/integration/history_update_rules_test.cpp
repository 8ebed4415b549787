// The update rules (pInfos-03667, 03758..03767, primitiveCount-03769): each fires, alone, when an update
// differs from its source's last executed build in what the rule names; updates that repeat the build stay
// silent. Device builds are checked at submission; host builds (vkBuildAccelerationStructuresKHR) when
// called, and since lavapipe has no host commands, only calls the layer skips (the monitor returns VK_TRUE)
// are made; their valid twins are unit tests (tests/unit/history_unit_test.cpp).
#include <catch2/catch_test_macros.hpp>

#include "history_helpers.h"

namespace asval_test {
namespace {

struct Rule {
  const char* what;
  const char* device_vuid;
  const char* host_vuid;
  Shape build;
  Shape update;
};

Shape With(void (*edit)(Shape&)) {
  Shape s;
  edit(s);
  return s;
}

std::vector<Rule> Rules() {
  return {
      {"source built without ALLOW_UPDATE", "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03667",
       "VUID-vkBuildAccelerationStructuresKHR-pInfos-03667",
       With([](Shape& s) { s.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR; }),
       With([](Shape& s) { s.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR; })},
      {"geometryCount", "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03758",
       "VUID-vkBuildAccelerationStructuresKHR-pInfos-03758", Shape{}, With([](Shape& s) { s.geometries = 3; })},
      {"flags", "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03759",
       "VUID-vkBuildAccelerationStructuresKHR-pInfos-03759", Shape{}, With([](Shape& s) {
         s.flags = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR |
                   VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_BUILD_BIT_KHR;
       })},
      {"type", "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03760",
       "VUID-vkBuildAccelerationStructuresKHR-pInfos-03760", Shape{},
       With([](Shape& s) { s.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR; })},
      {"geometryType", "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03761",
       "VUID-vkBuildAccelerationStructuresKHR-pInfos-03761", Shape{},
       With([](Shape& s) { s.geometry_type = VK_GEOMETRY_TYPE_AABBS_KHR; })},
      {"geometry flags", "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03762",
       "VUID-vkBuildAccelerationStructuresKHR-pInfos-03762", Shape{},
       With([](Shape& s) { s.geometry_flags = VK_GEOMETRY_NO_DUPLICATE_ANY_HIT_INVOCATION_BIT_KHR; })},
      {"vertexFormat", "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03763",
       "VUID-vkBuildAccelerationStructuresKHR-pInfos-03763", Shape{},
       With([](Shape& s) { s.vertex_format = VK_FORMAT_R32G32_SFLOAT; })},
      {"maxVertex", "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03764",
       "VUID-vkBuildAccelerationStructuresKHR-pInfos-03764", Shape{}, With([](Shape& s) { s.max_vertex = 5; })},
      {"indexType", "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03765",
       "VUID-vkBuildAccelerationStructuresKHR-pInfos-03765", Shape{},
       With([](Shape& s) { s.index_type = VK_INDEX_TYPE_UINT32; })},
      {"transformData made non-NULL", "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03766",
       "VUID-vkBuildAccelerationStructuresKHR-pInfos-03766", Shape{}, With([](Shape& s) { s.transform = true; })},
      {"transformData made NULL", "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03767",
       "VUID-vkBuildAccelerationStructuresKHR-pInfos-03767", With([](Shape& s) { s.transform = true; }), Shape{}},
      {"primitiveCount", "VUID-vkCmdBuildAccelerationStructuresKHR-primitiveCount-03769",
       "VUID-vkBuildAccelerationStructuresKHR-primitiveCount-03769", With([](Shape& s) { s.max_vertex = 5; }),
       With([](Shape& s) { s.triangles = 2; s.max_vertex = 5; })},
  };
}

void BuildAndSubmit(vkkit::Device& device, Blas& blas, const Shape& shape) {
  Commands commands(device);
  VkCommandBuffer cb = commands.Begin();
  blas.Build(cb, shape);
  commands.End(cb);
  REQUIRE(commands.Submit(cb) == VK_SUCCESS);
}

TEST_CASE("history: each update rule fires alone on its own mismatch (vkCmdBuildAccelerationStructuresKHR)",
          "[integration][history][passes-invalid-down]") {
  for (const Rule& rule : Rules()) {
    DYNAMIC_SECTION(rule.what) {
      HistoryFixture f("history");
      vkkit::Device& device = f.device();
      Inputs inputs(device);
      Blas blas(device, inputs);
      BuildAndSubmit(device, blas, rule.build);
      Commands commands(device);
      VkCommandBuffer cb = commands.Begin();
      blas.Update(cb, rule.update);
      commands.End(cb);
      f.monitor().Expect(rule.device_vuid);
      CHECK(commands.Submit(cb) == VK_ERROR_VALIDATION_FAILED_EXT);
      CHECK(f.monitor().Verify() == "");
    }
  }
}

TEST_CASE("history: each update rule fires alone on its own mismatch (vkBuildAccelerationStructuresKHR)",
          "[integration][history]") {
  for (const Rule& rule : Rules()) {
    DYNAMIC_SECTION(rule.what) {
      HistoryFixture f("history");
      vkkit::Device& device = f.device();
      Inputs inputs(device);
      Blas blas(device, inputs);
      BuildAndSubmit(device, blas, rule.build);
      f.monitor().Expect(rule.host_vuid);
      CHECK(blas.HostUpdate(rule.update) == VK_ERROR_VALIDATION_FAILED_EXT);
      std::vector<Message> messages = f.monitor().Take();
      REQUIRE(messages.size() == 1);
      CHECK(messages[0].id_name == rule.host_vuid);
      CHECK(messages[0].text.find("vkBuildAccelerationStructuresKHR(): pInfos[0]") != std::string::npos);
    }
  }
}

TEST_CASE("history valid twin: updates that repeat their source's last build stay silent", "[integration][history]") {
  const std::vector<Shape> shapes = {
      Shape{},
      With([](Shape& s) { s.geometries = 3; s.triangles = 2; }),
      With([](Shape& s) { s.index_type = VK_INDEX_TYPE_UINT32; s.transform = true; }),
      With([](Shape& s) { s.geometry_type = VK_GEOMETRY_TYPE_AABBS_KHR; s.triangles = 2; }),
      With([](Shape& s) {
        s.flags |= VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR;
        s.geometry_flags = VK_GEOMETRY_NO_DUPLICATE_ANY_HIT_INVOCATION_BIT_KHR;
        s.vertex_format = VK_FORMAT_R32G32_SFLOAT;
        s.max_vertex = 5;
      }),
  };
  HistoryFixture f;
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  Blas other(device, inputs);
  for (size_t i = 0; i < shapes.size(); ++i) {
    INFO("shape " << i);
    Commands commands(device);
    VkCommandBuffer cb = commands.Begin();
    blas.Build(cb, shapes[i]);
    commands.Barrier(cb);
    blas.Update(cb, shapes[i]);           // in place
    commands.Barrier(cb);
    other.Update(cb, shapes[i], &blas);   // into another structure
    commands.Barrier(cb);
    other.Update(cb, shapes[i]);          // and that one's history is the same build
    commands.End(cb);
    CHECK(commands.Submit(cb) == VK_SUCCESS);
    CHECK(f.monitor().Verify() == "");
  }
}

}  // namespace
}  // namespace asval_test
