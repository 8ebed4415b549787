// The capture's layer-specific messages that no Valid Usage rule backs, and the capture_warnings setting that
// switches each: ASVAL-Capture-FloatSpacing (off by default), ASVAL-Capture-DegenerateInstance (information, with
// capture = all) and ASVAL-Capture-UndefinedInput (on by default; its firing test is in capture_activity_test.cpp).
// The inputs are written on the device (vkCmdUpdateBuffer) in the command buffer of the build that reads them, so
// only the capture can know them; each submission is waited for, and the messages asserted after the wait.
#include <catch2/catch_test_macros.hpp>

#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include "capture_helpers.h"
#include "history_helpers.h"
#include "temp_report.h"

namespace asval_test {
namespace {

constexpr const char* kFloatSpacing = "ASVAL-Capture-FloatSpacing";
constexpr const char* kDegenerateInstance = "ASVAL-Capture-DegenerateInstance";
constexpr const char* kUndefinedInput = "ASVAL-Capture-UndefinedInput";
constexpr const char* kAllButSpacing = "undefined_input,non_finite_transform,degenerate_instance";
constexpr const char* kAll = "undefined_input,non_finite_transform,float_spacing,degenerate_instance";

// Two unit right triangles (R32G32B32_SFLOAT, the helpers' layout), the first at x = x0, the second at x = x1.
std::vector<uint32_t> TwoTriangles(float x0, float x1) {
  const float corner[3][2] = {{0, 0}, {1, 0}, {0, 1}};
  std::vector<uint32_t> words;
  for (uint32_t v = 0; v < 6; ++v) {
    words.push_back(Bits(corner[v % 3][0] + (v < 3 ? x0 : x1)));
    words.push_back(Bits(corner[v % 3][1]));
    words.push_back(Bits(0.0f));
  }
  return words;
}

Shape Triangles() {
  Shape s;
  s.triangles = 2;
  return s;
}

// A bottom-level structure over inputs the device writes, and the command buffers of a test.
class Rig {
 public:
  explicit Rig(HistoryFixture& f)
      : device_(f.device()), inputs_(device_, VK_BUFFER_USAGE_TRANSFER_DST_BIT), blas_(device_, inputs_),
        commands_(device_) {}
  vkkit::Device& device() { return device_; }
  Blas& blas() { return blas_; }

  void Run(const std::function<void(VkCommandBuffer)>& record) { SubmitAndWait(device_, RecordWith(commands_, record)); }
  // The vertices written on the device, then the (ALLOW_UPDATE: captured by default) build of the two triangles.
  void Build(const std::vector<uint32_t>& vertices) {
    Run([&](VkCommandBuffer cb) {
      vkCmdUpdateBuffer(cb, inputs_.buffer().buffer, Inputs::kVerticesOffset, vertices.size() * sizeof(uint32_t),
                        vertices.data());
      InputsWritten(cb);
      blas_.Build(cb, Triangles());
    });
  }

 private:
  vkkit::Device& device_;
  Inputs inputs_;
  Blas blas_;
  Commands commands_;
};

// The report file's lines (JSON, one per message: the test's messenger takes errors and warnings only) that
// carry `id` and `text`.
int ReportLines(const asval_test_common::TempReport& report, const char* id, const std::string& text) {
  int n = 0;
  for (const std::string& line : report.Lines()) {
    n += line.find(id) != std::string::npos && line.find(text) != std::string::npos;
  }
  return n;
}

}  // namespace

TEST_CASE("capture: with the float_spacing capture warning, a triangle far from the origin for its size is reported",
          "[integration][capture]") {
  HistoryFixture f(nullptr, {{"capture_warnings", kAll}});  // capture_float_spacing_permille: 10 (default)
  Rig rig(f);
  // Near 10^6, floats are 0.0625 apart: 62.5 thousandths of a unit triangle, over the threshold of 10.
  rig.Build(TwoTriangles(0.0f, 1.0e6f));
  CHECK(OnlyFinding(f.monitor(), kFloatSpacing, "geometry 0: 1 primitive(s) lie where 32-bit floats are spaced more "
                                                "than 10/1000 of their size apart (first: primitive 1") == "");
  // The twin: near 10^3 they are 0.00006 apart (0.06 thousandths): silent.
  rig.Build(TwoTriangles(0.0f, 1.0e3f));
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("capture: the float-spacing threshold follows capture_float_spacing_permille", "[integration][capture]") {
  // 62.5 thousandths near 10^6: under a threshold of 100, over one of 50.
  {
    HistoryFixture f(nullptr, {{"capture_warnings", kAll}, {"capture_float_spacing_permille", "100"}});
    Rig rig(f);
    rig.Build(TwoTriangles(0.0f, 1.0e6f));
    CHECK(f.monitor().Verify() == "");
  }
  HistoryFixture f(nullptr, {{"capture_warnings", kAll}, {"capture_float_spacing_permille", "50"}});
  Rig rig(f);
  rig.Build(TwoTriangles(0.0f, 1.0e6f));
  CHECK(OnlyFinding(f.monitor(), kFloatSpacing, "more than 50/1000 of their size apart") == "");
}

TEST_CASE("capture: float spacing is not scanned by default", "[integration][capture]") {
  HistoryFixture f;
  Rig rig(f);
  rig.Build(TwoTriangles(0.0f, 1.0e6f));
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("capture: capture_warnings without undefined_input leaves the undefined-input warning out",
          "[integration][capture]") {
  std::vector<uint32_t> vertices = TwoTriangles(0.0f, 2.0f);
  vertices[3 * 4 + 1] = kNan;  // triangle 1's second vertex: Y is NaN, X is not (reported by default)
  {
    HistoryFixture f(nullptr, {{"capture_warnings", "non_finite_transform"}});
    Rig rig(f);
    rig.Build(vertices);
    CHECK(f.monitor().Verify() == "");
  }
  HistoryFixture f(nullptr, {{"capture_warnings", kAllButSpacing}});
  Rig rig(f);
  rig.Build(vertices);
  CHECK(OnlyFinding(f.monitor(), kUndefinedInput, "geometry 0: 1 primitive(s)") == "");
}

TEST_CASE("capture: with capture=all, an instance of a structure without active primitive gets the "
          "degenerate-instance information",
          "[integration][capture]") {
  asval_test_common::TempReport report;
  HistoryFixture f(nullptr, {{"capture", "all"}, {"report_flags", "error,warn,info"}, {"report_file", report.path.c_str()}});
  Rig rig(f);
  Inputs solid_inputs(rig.device());
  Blas solid(rig.device(), solid_inputs);
  Tlas tlas(rig.device());
  std::vector<uint32_t> inactive = TwoTriangles(0.0f, 2.0f);
  inactive[0] = inactive[3 * 3] = kNan;  // X of each triangle's first vertex: both inactive
  rig.Build(inactive);
  rig.Run([&](VkCommandBuffer cb) { solid.Build(cb, Triangles()); });
  vkkit::Buffer instances = tlas.MakeInstances({&solid, &rig.blas()});
  rig.Run([&](VkCommandBuffer cb) { tlas.Record(cb, instances, 2, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR); });
  CHECK(ReportLines(report, kDegenerateInstance, "") == 1);
  CHECK(ReportLines(report, kDegenerateInstance, "geometry 0, instance 1 references") == 1);
  // The twin: the structure built again with active triangles, the same instances: nothing more.
  rig.Build(TwoTriangles(0.0f, 2.0f));
  rig.Run([&](VkCommandBuffer cb) { tlas.Record(cb, instances, 2, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR); });
  CHECK(ReportLines(report, kDegenerateInstance, "") == 1);
  CHECK(f.monitor().Verify() == "");
  rig.device().Destroy(instances);
}

TEST_CASE("capture: with capture=all and the float_spacing warning, an instance translated far for the primitives it "
          "references is reported",
          "[integration][capture]") {
  HistoryFixture f(nullptr, {{"capture", "all"}, {"capture_warnings", kAll}});
  Rig rig(f);
  Tlas tlas(rig.device());
  rig.Build(TwoTriangles(0.0f, 2.0f));  // unit triangles: the smallest primitive's size is 1
  vkkit::Buffer instances = tlas.MakeInstances({&rig.blas(), &rig.blas()});
  const auto translate = [&](uint32_t instance, float x) {
    auto* records = static_cast<VkAccelerationStructureInstanceKHR*>(instances.mapped);
    records[instance].transform.matrix[0][3] = x;
  };
  // Near 10^6 floats are 0.0625 apart: 62.5 thousandths of the smallest primitive, over the threshold of 10.
  translate(1, 1.0e6f);
  rig.Run([&](VkCommandBuffer cb) { tlas.Record(cb, instances, 2, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR); });
  CHECK(OnlyFinding(f.monitor(), kFloatSpacing, "geometry 0: 1 instance(s) are translated so far") == "");
  // The twin: near 10^3 (0.06 thousandths): silent.
  translate(1, 1.0e3f);
  rig.Run([&](VkCommandBuffer cb) { tlas.Record(cb, instances, 2, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR); });
  CHECK(f.monitor().Verify() == "");
  rig.device().Destroy(instances);
}

TEST_CASE("capture: with capture=updates (the default), degenerate instances are not reported",
          "[integration][capture]") {
  asval_test_common::TempReport report;
  HistoryFixture f(nullptr, {{"report_flags", "error,warn,info"}, {"report_file", report.path.c_str()}});
  Rig rig(f);
  Tlas tlas(rig.device());
  std::vector<uint32_t> inactive = TwoTriangles(0.0f, 2.0f);
  inactive[0] = inactive[3 * 3] = kNan;
  rig.Build(inactive);
  vkkit::Buffer instances = tlas.MakeInstances({&rig.blas()});
  rig.Run([&](VkCommandBuffer cb) { tlas.Record(cb, instances, 1, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR); });
  CHECK(ReportLines(report, kDegenerateInstance, "") == 0);
  CHECK(f.monitor().Verify() == "");
  rig.device().Destroy(instances);
}

}  // namespace asval_test
