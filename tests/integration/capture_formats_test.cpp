// Execution-time capture (issue 12, docs/capture.md) across vertex formats: for every format the layer's table
// decodes (asval/vertex_formats.h, DecodableVertexFormatsBegin/End) that the device accepts for acceleration-
// structure vertex buffers, non-indexed and with UINT16 and UINT32 indices, an update that writes a NaN X into
// a vertex of triangle 1 is reported (pInfos-03664) when the format has a NaN, and stays silent for UNORM/SNORM
// formats, which have none (always active: docs/builder.md, "Decisions"); a valid twin that moves the vertices
// stays silent. As in capture_activity_test.cpp, the inputs are written on the device (vkCmdUpdateBuffer) in
// the command buffer of the build or update that reads them, and each submission is waited for.
//
// The encodings and the expectations come from the table below, written by hand, not from the layer's table:
// a wrong row there (vertexBytes, hasNaN, the component kind) shows as a missed or an extra finding here. The
// vertices are tightly packed (vertexStride = the format's size), so the capture must copy exactly the last
// vertex's bytes; the summary the layer writes at vkDestroyDevice (ASVAL-History-Summary) is read back to see
// that every build and update was captured, whole (the byte count), and judged; for UNORM/SNORM formats that
// is what shows the silence was a judgement and not a skipped rule.
#include <catch2/catch_test_macros.hpp>

#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <regex>
#include <string>
#include <vector>

#include "asval/vertex_formats.h"
#include "capture_helpers.h"
#include "history_helpers.h"
#include "temp_report.h"

namespace asval_test {
namespace {

constexpr const char* kBecameInactive = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03664";

enum class Kind { kFloat, kSnorm, kUnorm, kPacked1010102 };

// How the test writes a vertex of a format: `components` components of `bits` bits each, in memory order
// R, G, B, A (X, Y, Z, W); the packed A2B10G10R10 holds X in bits 0..9, Y in 10..19, Z in 20..29 of one word.
struct Encoding {
  VkFormat format;
  const char* name;
  Kind kind;
  uint8_t bits;
  uint8_t components;
  uint32_t bytes() const { return kind == Kind::kPacked1010102 ? 4 : bits / 8 * components; }
  bool has_nan() const { return kind == Kind::kFloat; }
};

// The candidates: the formats the layer decodes today, and the 64-bit float ones a device may accept too.
constexpr Encoding kEncodings[] = {
    {VK_FORMAT_R32G32_SFLOAT, "R32G32_SFLOAT", Kind::kFloat, 32, 2},
    {VK_FORMAT_R32G32B32_SFLOAT, "R32G32B32_SFLOAT", Kind::kFloat, 32, 3},
    {VK_FORMAT_R32G32B32A32_SFLOAT, "R32G32B32A32_SFLOAT", Kind::kFloat, 32, 4},
    {VK_FORMAT_R16G16_SFLOAT, "R16G16_SFLOAT", Kind::kFloat, 16, 2},
    {VK_FORMAT_R16G16B16_SFLOAT, "R16G16B16_SFLOAT", Kind::kFloat, 16, 3},
    {VK_FORMAT_R16G16B16A16_SFLOAT, "R16G16B16A16_SFLOAT", Kind::kFloat, 16, 4},
    {VK_FORMAT_R16G16_SNORM, "R16G16_SNORM", Kind::kSnorm, 16, 2},
    {VK_FORMAT_R16G16B16_SNORM, "R16G16B16_SNORM", Kind::kSnorm, 16, 3},
    {VK_FORMAT_R16G16B16A16_SNORM, "R16G16B16A16_SNORM", Kind::kSnorm, 16, 4},
    {VK_FORMAT_R16G16_UNORM, "R16G16_UNORM", Kind::kUnorm, 16, 2},
    {VK_FORMAT_R16G16B16_UNORM, "R16G16B16_UNORM", Kind::kUnorm, 16, 3},
    {VK_FORMAT_R16G16B16A16_UNORM, "R16G16B16A16_UNORM", Kind::kUnorm, 16, 4},
    {VK_FORMAT_R8G8_SNORM, "R8G8_SNORM", Kind::kSnorm, 8, 2},
    {VK_FORMAT_R8G8B8_SNORM, "R8G8B8_SNORM", Kind::kSnorm, 8, 3},
    {VK_FORMAT_R8G8B8A8_SNORM, "R8G8B8A8_SNORM", Kind::kSnorm, 8, 4},
    {VK_FORMAT_R8G8_UNORM, "R8G8_UNORM", Kind::kUnorm, 8, 2},
    {VK_FORMAT_R8G8B8_UNORM, "R8G8B8_UNORM", Kind::kUnorm, 8, 3},
    {VK_FORMAT_R8G8B8A8_UNORM, "R8G8B8A8_UNORM", Kind::kUnorm, 8, 4},
    {VK_FORMAT_A2B10G10R10_UNORM_PACK32, "A2B10G10R10_UNORM_PACK32", Kind::kPacked1010102, 10, 3},
    {VK_FORMAT_R64G64_SFLOAT, "R64G64_SFLOAT", Kind::kFloat, 64, 2},
    {VK_FORMAT_R64G64B64_SFLOAT, "R64G64B64_SFLOAT", Kind::kFloat, 64, 3},
    {VK_FORMAT_R64G64B64A64_SFLOAT, "R64G64B64A64_SFLOAT", Kind::kFloat, 64, 4},
};

const Encoding* FindEncoding(VkFormat format) {
  for (const Encoding& e : kEncodings) {
    if (e.format == format) return &e;
  }
  return nullptr;
}

bool LayerDecodes(VkFormat format) {
  for (const asval::VertexFormatInfo* f = asval::DecodableVertexFormatsBegin(); f != asval::DecodableVertexFormatsEnd();
       ++f) {
    if (f->format == format) return true;
  }
  return false;
}

// VK_FORMAT_FEATURE_ACCELERATION_STRUCTURE_VERTEX_BUFFER_BIT_KHR in the device's bufferFeatures.
bool DeviceAccepts(VkPhysicalDevice gpu, VkFormat format) {
  VkFormatProperties properties{};
  vkGetPhysicalDeviceFormatProperties(gpu, format, &properties);
  return (properties.bufferFeatures & VK_FORMAT_FEATURE_ACCELERATION_STRUCTURE_VERTEX_BUFFER_BIT_KHR) != 0;
}

// The formats of the layer's list (in its order) that the device accepts, asked once per process.
struct Formats {
  std::vector<const Encoding*> tested;     // decoded by the layer, accepted by the device
  std::vector<std::string> not_accepted;   // decoded by the layer, refused by the device: skipped
  std::vector<std::string> not_encodable;  // decoded by the layer, missing from kEncodings: a failure
  std::vector<std::string> not_decoded;    // candidates the device accepts and the layer does not decode
};

const Formats& DeviceFormats() {
  static const Formats formats = [] {
    Formats out;
    HistoryFixture f;
    const VkPhysicalDevice gpu = f.instance().FindRayTracingGpu();
    for (const asval::VertexFormatInfo* info = asval::DecodableVertexFormatsBegin();
         info != asval::DecodableVertexFormatsEnd(); ++info) {
      const Encoding* e = FindEncoding(info->format);
      if (!e) {
        out.not_encodable.push_back("VkFormat " + std::to_string(info->format));
      } else if (DeviceAccepts(gpu, e->format)) {
        out.tested.push_back(e);
      } else {
        out.not_accepted.push_back(e->name);
      }
    }
    for (const Encoding& e : kEncodings) {
      if (!LayerDecodes(e.format) && DeviceAccepts(gpu, e.format)) out.not_decoded.push_back(e.name);
    }
    return out;
  }();
  return formats;
}

std::string Join(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out.empty() ? "(none)" : out;
}

const char* IndexName(VkIndexType type) {
  switch (type) {
    case VK_INDEX_TYPE_UINT16: return "UINT16";
    case VK_INDEX_TYPE_UINT32: return "UINT32";
    default: return "non-indexed";
  }
}

uint32_t IndexBytes(VkIndexType type) {
  return type == VK_INDEX_TYPE_UINT16 ? 2 : type == VK_INDEX_TYPE_UINT32 ? 4 : 0;
}

// The bits of `value` as an IEEE float of `bits` bits (16: only values exact in binary16, as the tests'
// coordinates are: multiples of 1/4 in [0, 1]).
uint64_t FloatBits(float value, uint8_t bits) {
  if (bits == 32) {
    uint32_t word;
    std::memcpy(&word, &value, sizeof(word));
    return word;
  }
  if (bits == 64) {
    const double d = value;
    uint64_t word;
    std::memcpy(&word, &d, sizeof(word));
    return word;
  }
  if (value == 0) return 0;
  int e = 0;
  const float m = std::frexp(value, &e);  // value = m * 2^e, m in [0.5, 1): (1 + f / 1024) * 2^(e - 1)
  return static_cast<uint64_t>(e - 1 + 15) << 10 | static_cast<uint64_t>(std::lround((2 * m - 1) * 1024));
}

// A component's bits: the value, or the NaN the format has (a quiet NaN of its width) or, for UNORM/SNORM, which
// have none, all ones: the bits a float of that width would read as NaN.
uint64_t ComponentBits(const Encoding& e, float value, bool nan) {
  const uint64_t ones = e.bits == 64 ? ~uint64_t{0} : (uint64_t{1} << e.bits) - 1;
  switch (e.kind) {
    case Kind::kFloat:
      if (!nan) return FloatBits(value, e.bits);
      return e.bits == 16 ? 0x7e00u : e.bits == 32 ? 0x7fc00000u : 0x7ff8000000000000u;
    case Kind::kSnorm:
      if (nan) return ones;
      return static_cast<uint64_t>(std::lround(value * static_cast<float>((1u << (e.bits - 1)) - 1))) & ones;
    case Kind::kUnorm:
    case Kind::kPacked1010102:
      if (nan) return ones;
      return static_cast<uint64_t>(std::lround(value * static_cast<float>(ones)));
  }
  return 0;
}

// Six vertices in `e`, tightly packed, forming triangles (0, 1, 2) and (3, 4, 5): right triangles with legs 0.5
// at z = 0 and z = 0.5 (2-component formats: both at z = 0), moved by dx along X; W is 0. The X of vertex
// `nan_vertex` (if any) holds the NaN bits. Padded with zeros to whole words for vkCmdUpdateBuffer.
std::vector<uint8_t> Vertices(const Encoding& e, float dx = 0, int nan_vertex = -1) {
  const float corner[3][2] = {{0, 0}, {0.5f, 0}, {0, 0.5f}};
  std::vector<uint8_t> bytes(6 * e.bytes(), 0);
  for (uint32_t v = 0; v < 6; ++v) {
    const float xyz[3] = {corner[v % 3][0] + dx, corner[v % 3][1], 0.5f * static_cast<float>(v / 3)};
    const bool nan_x = static_cast<int>(v) == nan_vertex;
    uint8_t* out = bytes.data() + v * e.bytes();
    if (e.kind == Kind::kPacked1010102) {
      uint32_t word = 0;
      for (uint32_t c = 0; c < 3; ++c) {
        word |= static_cast<uint32_t>(ComponentBits(e, xyz[c], c == 0 && nan_x)) << (10 * c);
      }
      std::memcpy(out, &word, 4);
      continue;
    }
    for (uint32_t c = 0; c < e.components; ++c) {
      const uint64_t word = c < 3 ? ComponentBits(e, xyz[c], c == 0 && nan_x) : ComponentBits(e, 0, false);
      std::memcpy(out + c * (e.bits / 8), &word, e.bits / 8);  // little-endian: the low bytes
    }
  }
  bytes.resize((bytes.size() + 3) & ~size_t{3}, 0);
  return bytes;
}

// Triangles (0, 1, 2) and (3, 4, 5) as `type`'s values, in whole words.
std::vector<uint32_t> Indices(VkIndexType type) {
  if (type == VK_INDEX_TYPE_UINT16) return {0u | 1u << 16, 2u | 3u << 16, 4u | 5u << 16};
  return {0, 1, 2, 3, 4, 5};
}

// One structure (two triangles, ALLOW_UPDATE) over inputs of its own in `e`'s format, written on the device.
class FormatRig {
 public:
  FormatRig(HistoryFixture& f, const Encoding& e, VkIndexType type)
      : inputs_(f.device(), VK_BUFFER_USAGE_TRANSFER_DST_BIT), blas_(f.device(), inputs_), commands_(f.device()) {
    shape_.triangles = 2;
    shape_.vertex_format = e.format;
    shape_.vertex_stride = e.bytes();
    shape_.index_type = type;
  }

  // The build (with the indices written too) or the update, of `vertices`, submitted and waited for.
  void Build(const std::vector<uint8_t>& vertices) { Run(vertices, true); }
  void Update(const std::vector<uint8_t>& vertices) { Run(vertices, false); }

 private:
  void Run(const std::vector<uint8_t>& vertices, bool build) {
    VkCommandBuffer cb = commands_.Begin();
    const VkBuffer buffer = inputs_.buffer().buffer;
    vkCmdUpdateBuffer(cb, buffer, Inputs::kVerticesOffset, vertices.size(), vertices.data());
    if (build && shape_.index_type != VK_INDEX_TYPE_NONE_KHR) {
      const std::vector<uint32_t> indices = Indices(shape_.index_type);
      vkCmdUpdateBuffer(cb, buffer, Inputs::kIndicesOffset, indices.size() * sizeof(uint32_t), indices.data());
    }
    InputsWritten(cb);  // the writes made visible to the build stage's reads of the inputs
    if (build) {
      blas_.Build(cb, shape_);
    } else {
      blas_.Update(cb, shape_);
    }
    commands_.End(cb);
    REQUIRE(commands_.Submit(cb) == VK_SUCCESS);  // vkQueueWaitIdle: where the layer reads the captures
  }

  Inputs inputs_;
  Blas blas_;
  Commands commands_;
  Shape shape_;
};

// What the layer's capture summary (ASVAL-History-Summary at vkDestroyDevice) counted.
struct CaptureSummary {
  bool found = false;
  uint64_t infos = 0, bytes = 0, updates_judged = 0, not_captured = 0;
  std::string line;
};

CaptureSummary ReadCaptureSummary(const asval_test_common::TempReport& report) {
  static const std::regex pattern(
      R"(Execution-time capture: (\d+) build infos captured \((\d+) bytes\), (\d+) updates judged on their )"
      R"(captured activity; (\d+) infos)");
  CaptureSummary s;
  for (const std::string& line : report.Lines()) {
    if (!nlohmann::json::accept(line)) continue;
    const nlohmann::json j = nlohmann::json::parse(line);
    if (!j.contains("message") || !j["message"].is_string()) continue;
    const std::string message = j["message"].get<std::string>();
    std::smatch m;
    if (!std::regex_search(message, m, pattern)) continue;
    s.found = true;
    s.infos = std::stoull(m[1]);
    s.bytes = std::stoull(m[2]);
    s.updates_judged = std::stoull(m[3]);
    s.not_captured = std::stoull(m[4]);
    s.line = message;
  }
  return s;
}

TEST_CASE("capture formats: the vertex formats tested are the layer's that the device accepts",
          "[integration][capture]") {
  const Formats& formats = DeviceFormats();
  std::vector<std::string> tested;
  for (const Encoding* e : formats.tested) tested.push_back(e->name);
  WARN("vertex formats tested (the layer decodes them, the device accepts them): " << Join(tested)
       << "\nskipped, the device does not accept them: " << Join(formats.not_accepted)
       << "\naccepted by the device, not decoded by the layer (their updates are not judged): "
       << Join(formats.not_decoded));
  // A format the layer decodes and the test cannot write would go untested without notice.
  INFO("decoded by the layer, unknown to the test's encodings: " << Join(formats.not_encodable));
  CHECK(formats.not_encodable.empty());
  CHECK_FALSE(formats.tested.empty());
}

// Every format the device accepts, with indices of `type`: one section (one device) per format. One test case
// per index type, so that a process creates at most one instance per format (a driver may refuse more than ~29).
void CheckFormats(VkIndexType type) {
  for (const Encoding* e : DeviceFormats().tested) {
    {
      DYNAMIC_SECTION(e->name << ", " << IndexName(type)) {
        asval_test_common::TempReport report;
        uint64_t infos = 0, updates = 0;
        {
          // The bytes counted below are those copied: the method is pinned (auto reduces on a GPU), unless the
          // environment asks for reduce (it wins over the API: integration_capture_reduce).
          HistoryFixture f(nullptr, {{"report_file", report.path.c_str()},
                                     {"report_flags", "error,warn,info"},
                                     {"capture_method", "copy"}});
          // The negative: triangle 1's second vertex gets the NaN bits in its X.
          FormatRig rig(f, *e, type);
          rig.Build(Vertices(*e));
          CHECK(f.monitor().Verify() == "");
          rig.Update(Vertices(*e, 0, 4));
          if (e->has_nan()) {
            CHECK(OnlyFinding(f.monitor(), kBecameInactive, ": primitive 1") == "");
          } else {
            CHECK(f.monitor().Verify() == "");  // always active: no NaN in the format
          }
          // The valid twin: a refit that moves every vertex, then (formats with NaN) a probe that makes
          // triangle 0 inactive, to show the twin's update was judged.
          FormatRig twin(f, *e, type);
          twin.Build(Vertices(*e));
          twin.Update(Vertices(*e, 0.25f));
          CHECK(f.monitor().Verify() == "");
          infos = 4;
          updates = 2;
          if (e->has_nan()) {
            twin.Update(Vertices(*e, 0.25f, 0));
            CHECK(OnlyFinding(f.monitor(), kBecameInactive, ": primitive 0") == "");
            ++infos;
            ++updates;
          }
        }  // the rigs, then the device: vkDestroyDevice writes the summary
        // Every build and update captured, each its six vertices (and six indices) exactly, and every update
        // judged on the captured bytes.
        const CaptureSummary s = ReadCaptureSummary(report);
        INFO(s.line);
        REQUIRE(s.found);
        CHECK(s.infos == infos);
        if (!CaptureReducedRun()) {
          CHECK(s.bytes == infos * 6 * (e->bytes() + IndexBytes(type)));
        } else {  // per info: its 64-byte job, three one-word bit arrays, and indexed one 16-byte index hash block
          CHECK(s.bytes == infos * (64 + 3 * 4 + (IndexBytes(type) != 0 ? 16 : 0)));
        }
        CHECK(s.updates_judged == updates);
        CHECK(s.not_captured == 0);
      }
    }
  }
}

TEST_CASE("capture formats: a NaN X in an update is reported for formats with NaN, never for UNORM/SNORM "
          "(pInfos-03664); a refit in any format stays silent: non-indexed",
          "[integration][capture]") {
  CheckFormats(VK_INDEX_TYPE_NONE_KHR);
}

TEST_CASE("capture formats: a NaN X in an update is reported for formats with NaN, never for UNORM/SNORM "
          "(pInfos-03664); a refit in any format stays silent: 16-bit indices",
          "[integration][capture]") {
  CheckFormats(VK_INDEX_TYPE_UINT16);
}

TEST_CASE("capture formats: a NaN X in an update is reported for formats with NaN, never for UNORM/SNORM "
          "(pInfos-03664); a refit in any format stays silent: 32-bit indices",
          "[integration][capture]") {
  CheckFormats(VK_INDEX_TYPE_UINT32);
}

}  // namespace
}  // namespace asval_test
