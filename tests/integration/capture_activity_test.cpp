// Execution-time capture (issue 12): the rules that compare an update's primitives with its source's last
// executed build (pInfos-03663, 03664, 03768), judged on the bytes the inputs held when the commands ran. The
// tests write the inputs on the device (vkCmdUpdateBuffer, vkCmdFillBuffer), in the command buffer of the
// build or update that reads them: at submission the layer cannot know those bytes, only the capture can. Each
// submission is waited for, and the findings are asserted once the wait returned (the layer reports them in the
// wait). A primitive is inactive when the first (X) component of one of its vertices is NaN, an AABB when its
// minX is NaN. Besides the runs of every integration test, these run with the Khronos layer's synchronization
// validation below asval (CMakeLists.txt: integration_capture_sync_validation): the layer's inserted barriers
// and copies must not race with the tests' commands, nor with each other.
#include <catch2/catch_test_macros.hpp>

#include <cstring>
#include <functional>
#include <thread>

#include "capture_helpers.h"
#include "history_helpers.h"
#include "temp_report.h"

namespace asval_test {
namespace {

constexpr const char* kBecameActive = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03663";
constexpr const char* kBecameInactive = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03664";
constexpr const char* kIndicesChanged = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03768";

constexpr uint32_t kOtherNan = 0xffc00001u;  // a NaN with another sign and payload
constexpr VkDeviceSize kAabbBytes = 24;

// Where minX of AABB a lies in the inputs buffer (capture_helpers.h: Component, the vertices' components).
VkDeviceSize MinX(uint32_t a) { return Inputs::kAabbsOffset + kAabbBytes * a; }

// Two unit boxes side by side, moved by dx along X.
std::vector<uint32_t> Boxes(float dx = 0) {
  std::vector<uint32_t> words;
  for (float x : {0.0f, 2.0f}) {
    for (float value : {x + dx, 0.0f, 0.0f, x + dx + 1, 1.0f, 1.0f}) words.push_back(Bits(value));
  }
  return words;
}

// The indices of triangles (0, 1, 2) and (3, 4, 5), as 32-bit words of the index type's values.
std::vector<uint32_t> Indices(VkIndexType type) {
  if (type == VK_INDEX_TYPE_UINT16) return {0u | 1u << 16, 2u | 3u << 16, 4u | 5u << 16};
  return {0, 1, 2, 3, 4, 5};
}

Shape Triangles() {
  Shape s;
  s.triangles = 2;
  return s;
}

Shape Indexed(VkIndexType type) {
  Shape s = Triangles();
  s.index_type = type;
  return s;
}

Shape Aabbs() {
  Shape s = Triangles();
  s.geometry_type = VK_GEOMETRY_TYPE_AABBS_KHR;
  return s;
}

// One structure over inputs the device writes, and the command buffers of a test.
class Rig {
 public:
  explicit Rig(HistoryFixture& f)
      : device_(f.device()), inputs_(device_, VK_BUFFER_USAGE_TRANSFER_DST_BIT), blas_(device_, inputs_),
        other_(device_, inputs_), commands_(device_) {}

  Blas& blas() { return blas_; }
  Blas& other() { return other_; }  // a second structure over the same inputs
  vkkit::Device& device() { return device_; }
  Commands& commands() { return commands_; }

  // 4-byte words written at `offset` of the inputs buffer when the command buffer executes.
  void Write(VkCommandBuffer cb, VkDeviceSize offset, const std::vector<uint32_t>& words) {
    vkCmdUpdateBuffer(cb, inputs_.buffer().buffer, offset, words.size() * sizeof(uint32_t), words.data());
  }
  void Fill(VkCommandBuffer cb, VkDeviceSize offset, uint32_t word) {
    vkCmdFillBuffer(cb, inputs_.buffer().buffer, offset, sizeof(uint32_t), word);
  }

  // The writes recorded so far made visible to the build or update that follows (inputs are read by the
  // build stage as shader reads), then the build or update.
  void Build(VkCommandBuffer cb, const Shape& shape) {
    InputsWritten(cb);
    blas_.Build(cb, shape);
  }
  void Update(VkCommandBuffer cb, const Shape& shape) {
    InputsWritten(cb);
    blas_.Update(cb, shape);
  }
  // Between a build and an update in one command buffer: the update reads what the build wrote, and the
  // writes of the inputs recorded in between wait until the build has read them.
  void AfterBuild(VkCommandBuffer cb) {
    commands_.Barrier(cb);
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
                         0, nullptr, 0, nullptr, 0, nullptr);
  }

  // The writes recorded so far made visible to the build stage's reads.
  void InputsWritten(VkCommandBuffer cb) { asval_test::InputsWritten(cb); }

  // A new command buffer holding what `record` records.
  VkCommandBuffer Record(const std::function<void(VkCommandBuffer)>& record) { return RecordWith(commands_, record); }

  // Submits cb and waits for it to complete in the way `wait` says.
  void Run(VkCommandBuffer cb, Wait wait = Wait::kQueueIdle) { SubmitAndWait(device_, cb, wait); }

 private:
  vkkit::Device& device_;
  Inputs inputs_;
  Blas blas_;
  Blas other_;
  Commands commands_;
};

// Whether the comparisons of the structure's updates are live: an update that now makes primitive 0 inactive
// (a NaN X over vertex 0, or over box 0's minX) must be reported. A valid twin's silence only means something if
// its updates were judged, and a rule skipped for unknown bytes is silent too: this finding needs the last
// update's activity to be known.
std::string Probe(Rig& rig, Monitor& monitor, const Shape& shape) {
  rig.Run(rig.Record([&](VkCommandBuffer cb) {
    rig.Fill(cb, shape.geometry_type == VK_GEOMETRY_TYPE_AABBS_KHR ? MinX(0) : Component(0, 0), kNan);
    rig.Update(cb, shape);
  }));
  return OnlyFinding(monitor, kBecameInactive, ": primitive 0");
}

// The valid first build of triangles (2, non-indexed), written on the device.
void BuildTriangles(Rig& rig, const std::vector<uint32_t>& vertices = Vertices()) {
  rig.Run(rig.Record([&](VkCommandBuffer cb) {
    rig.Write(cb, Component(0, 0), vertices);
    rig.Build(cb, Triangles());
  }));
}

TEST_CASE("capture: an update that makes an active triangle inactive is reported (pInfos-03664)",
          "[integration][capture]") {
  // Each way the app learns of completion is a point where the layer reads the captures.
  const std::vector<std::pair<const char*, Wait>> waits = {{"vkQueueWaitIdle", Wait::kQueueIdle},
                                                           {"vkWaitForFences", Wait::kFence},
                                                           {"vkGetFenceStatus", Wait::kFenceStatus},
                                                           {"vkDeviceWaitIdle", Wait::kDeviceIdle}};
  for (const auto& [name, wait] : waits) {
    DYNAMIC_SECTION(name) {
      HistoryFixture f;
      Rig rig(f);
      BuildTriangles(rig);
      CHECK(f.monitor().Verify() == "");
      rig.Run(rig.Record([&](VkCommandBuffer cb) {
        rig.Fill(cb, Component(4, 0), kNan);  // triangle 1's second vertex
        rig.Update(cb, Triangles());
      }),
              wait);
      CHECK(OnlyFinding(f.monitor(), kBecameInactive, ": primitive 1") == "");
    }
  }
}

TEST_CASE("capture: an update that makes an inactive triangle active is reported (pInfos-03663)",
          "[integration][capture]") {
  HistoryFixture f;
  Rig rig(f);
  // Triangle 1 is inactive in the build: its first vertex's X written as NaN on the device. (One write: a fill
  // over bytes the same command buffer just updated would need a transfer barrier of its own.)
  rig.Run(rig.Record([&](VkCommandBuffer cb) {
    std::vector<uint32_t> vertices = Vertices();
    vertices[3 * 3] = kNan;
    rig.Write(cb, Component(0, 0), vertices);
    rig.Build(cb, Triangles());
  }),
          Wait::kFence);
  CHECK(f.monitor().Verify() == "");
  rig.Run(rig.Record([&](VkCommandBuffer cb) {
    rig.Write(cb, Component(3, 0), {Bits(0.0f)});
    rig.Update(cb, Triangles());
  }),
          Wait::kFence);
  CHECK(OnlyFinding(f.monitor(), kBecameActive, ": primitive 1") == "");
}

TEST_CASE("capture: an update with other index values is reported (pInfos-03768)", "[integration][capture]") {
  for (VkIndexType type : {VK_INDEX_TYPE_UINT32, VK_INDEX_TYPE_UINT16}) {
    DYNAMIC_SECTION((type == VK_INDEX_TYPE_UINT32 ? "UINT32" : "UINT16")) {
      HistoryFixture f;
      Rig rig(f);
      rig.Run(rig.Record([&](VkCommandBuffer cb) {
        rig.Write(cb, Component(0, 0), Vertices());
        rig.Write(cb, Inputs::kIndicesOffset, Indices(type));
        rig.Build(cb, Indexed(type));
      }));
      CHECK(f.monitor().Verify() == "");
      // Triangle 0 becomes (0, 1, 3): in range, not degenerate, still active; only the index values differ.
      rig.Run(rig.Record([&](VkCommandBuffer cb) {
        if (type == VK_INDEX_TYPE_UINT32) {
          rig.Fill(cb, Inputs::kIndicesOffset + 2 * 4, 3);
        } else {
          rig.Fill(cb, Inputs::kIndicesOffset + 4, 3u | 3u << 16);  // indices 2 and 3, both 3
        }
        rig.Update(cb, Indexed(type));
      }));
      CHECK(OnlyFinding(f.monitor(), kIndicesChanged, "index values differ") == "");
    }
  }
}

TEST_CASE("capture: an update that makes an AABB inactive is reported (pInfos-03664)", "[integration][capture]") {
  HistoryFixture f;
  Rig rig(f);
  rig.Run(rig.Record([&](VkCommandBuffer cb) {
    rig.Write(cb, Inputs::kAabbsOffset, Boxes());
    rig.Build(cb, Aabbs());
  }));
  CHECK(f.monitor().Verify() == "");
  rig.Run(rig.Record([&](VkCommandBuffer cb) {
    rig.Fill(cb, MinX(1), kNan);
    rig.Update(cb, Aabbs());
  }));
  CHECK(OnlyFinding(f.monitor(), kBecameInactive, ": primitive 1") == "");
}

TEST_CASE("capture: a build and an update in one command buffer are each judged on their own bytes",
          "[integration][capture]") {
  // The capture of the build holds the vertices before the NaN is written, the update's those after.
  HistoryFixture f;
  Rig rig(f);
  rig.Run(rig.Record([&](VkCommandBuffer cb) {
    rig.Write(cb, Component(0, 0), Vertices());
    rig.Build(cb, Triangles());
    rig.AfterBuild(cb);
    rig.Fill(cb, Component(5, 0), kNan);
    rig.Update(cb, Triangles());
  }));
  CHECK(OnlyFinding(f.monitor(), kBecameInactive, ": primitive 1") == "");
}

TEST_CASE("capture: a command buffer submitted again is judged on the bytes of each execution",
          "[integration][capture]") {
  // The update command buffer writes nothing; what it reads changes between its submissions.
  HistoryFixture f;
  Rig rig(f);
  BuildTriangles(rig);
  VkCommandBuffer update = rig.Record([&](VkCommandBuffer cb) { rig.Update(cb, Triangles()); });
  VkCommandBuffer nan = rig.Record([&](VkCommandBuffer cb) { rig.Fill(cb, Component(0, 0), kNan); });
  VkCommandBuffer finite = rig.Record([&](VkCommandBuffer cb) { rig.Write(cb, Component(0, 0), {Bits(0.0f)}); });
  rig.Run(update);
  rig.Run(update);
  CHECK(f.monitor().Verify() == "");
  rig.Run(nan);
  rig.Run(update);  // triangle 0 made inactive
  CHECK(OnlyFinding(f.monitor(), kBecameInactive, ": primitive 0") == "");
  rig.Run(update);  // inactive in its source (the previous execution) too
  CHECK(f.monitor().Verify() == "");
  rig.Run(finite);
  rig.Run(update);  // active again
  CHECK(OnlyFinding(f.monitor(), kBecameActive, ": primitive 0") == "");
}

TEST_CASE("capture: updates are compared with their source's last build in submission order",
          "[integration][capture]") {
  HistoryFixture f;
  Rig rig(f);
  SECTION("the build and the update in two command buffers of one vkQueueSubmit") {
    VkCommandBuffer build = rig.Record([&](VkCommandBuffer cb) {
      rig.Write(cb, Component(0, 0), Vertices());
      rig.Build(cb, Triangles());
    });
    VkCommandBuffer update = rig.Record([&](VkCommandBuffer cb) {
      rig.AfterBuild(cb);
      rig.Fill(cb, Component(4, 0), kNan);
      rig.Update(cb, Triangles());
    });
    REQUIRE(rig.commands().Submit({build, update}) == VK_SUCCESS);
  }
  SECTION("the update recorded before the build, submitted after it; both in flight until one wait") {
    VkCommandBuffer update = rig.Record([&](VkCommandBuffer cb) {
      rig.AfterBuild(cb);
      rig.Fill(cb, Component(4, 0), kNan);
      rig.Update(cb, Triangles());
    });
    VkCommandBuffer build = rig.Record([&](VkCommandBuffer cb) {
      rig.Write(cb, Component(0, 0), Vertices());
      rig.Build(cb, Triangles());
    });
    // Two submissions to one queue: the second's commands start after the first's complete (the app's
    // barrier at the start of `update` orders them), and nothing is read until the wait.
    for (VkCommandBuffer cb : {build, update}) {
      VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
      submit.commandBufferCount = 1;
      submit.pCommandBuffers = &cb;
      REQUIRE(vkQueueSubmit(rig.device().queue(), 1, &submit, VK_NULL_HANDLE) == VK_SUCCESS);
    }
    REQUIRE(vkQueueWaitIdle(rig.device().queue()) == VK_SUCCESS);
  }
  CHECK(OnlyFinding(f.monitor(), kBecameInactive, ": primitive 1") == "");
}

TEST_CASE("capture: an update is compared with the activity its source got from a build or a clone",
          "[integration][capture]") {
  HistoryFixture f;
  Rig rig(f);
  BuildTriangles(rig);
  SECTION("an update from one structure into another") {
    rig.Run(rig.Record([&](VkCommandBuffer cb) {
      rig.Fill(cb, Component(4, 0), kNan);
      rig.InputsWritten(cb);
      rig.other().Update(cb, Triangles(), &rig.blas());
    }));
    CHECK(OnlyFinding(f.monitor(), kBecameInactive, ": primitive 1") == "");
  }
  SECTION("an update in place of a clone") {
    rig.Run(rig.Record([&](VkCommandBuffer cb) {
      CmdCopy(rig.device(), cb, rig.blas().handle(), rig.other().handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR);
    }));
    CHECK(f.monitor().Verify() == "");
    rig.Run(rig.Record([&](VkCommandBuffer cb) {
      rig.Fill(cb, Component(4, 0), kNan);
      rig.InputsWritten(cb);
      rig.other().Update(cb, Triangles());
    }));
    CHECK(OnlyFinding(f.monitor(), kBecameInactive, ": primitive 1") == "");
  }
}

TEST_CASE("capture: primitives are counted from the build range's primitiveOffset and firstVertex",
          "[integration][capture]") {
  // Each section's range skips the first vertex, index triple or box: a NaN there is outside the structure,
  // one in the range's last primitive makes primitive 1 inactive.
  struct Case {
    const char* what;
    Shape shape;
    std::vector<uint32_t> indices;  // 32-bit, empty: non-indexed
    VkDeviceSize outside;           // a word the range does not read as a primitive's first component
    VkDeviceSize in_primitive_1;    // a word that is the first component of one of primitive 1's vertices
  };
  Shape offset_vertices = Triangles();
  offset_vertices.primitive_offset = kVertexBytes;
  offset_vertices.max_vertex = 7;
  Shape first_vertex = Triangles();
  first_vertex.first_vertex = 1;
  first_vertex.max_vertex = 6;
  Shape offset_indices = Indexed(VK_INDEX_TYPE_UINT32);
  offset_indices.primitive_offset = 3 * 4;
  Shape indexed_first_vertex = Indexed(VK_INDEX_TYPE_UINT32);
  indexed_first_vertex.first_vertex = 1;
  indexed_first_vertex.max_vertex = 6;
  Shape offset_boxes = Aabbs();
  offset_boxes.primitive_offset = kAabbBytes;
  const std::vector<Case> cases = {
      {"non-indexed, primitiveOffset one vertex", offset_vertices, {}, Component(0, 0), Component(6, 0)},
      {"non-indexed, firstVertex 1", first_vertex, {}, Component(0, 0), Component(6, 0)},
      // Triangles (3, 4, 5) and (0, 1, 2) from the fourth index on.
      {"indexed, primitiveOffset three indices", offset_indices, {6, 6, 6, 3, 4, 5, 0, 1, 2}, Component(6, 0),
       Component(1, 0)},
      // Triangles (1, 2, 3) and (4, 5, 6).
      {"indexed, firstVertex 1", indexed_first_vertex, {0, 1, 2, 3, 4, 5}, Component(0, 0), Component(6, 0)},
      {"AABBs, primitiveOffset one box", offset_boxes, {}, MinX(0), MinX(2)},
  };
  for (const Case& c : cases) {
    DYNAMIC_SECTION(c.what) {
      HistoryFixture f;
      Rig rig(f);
      rig.Run(rig.Record([&](VkCommandBuffer cb) {
        if (c.shape.geometry_type == VK_GEOMETRY_TYPE_AABBS_KHR) {
          std::vector<uint32_t> boxes = Boxes();
          const std::vector<uint32_t> third = Boxes(4.0f);
          boxes.insert(boxes.end(), third.begin(), third.begin() + 6);
          rig.Write(cb, Inputs::kAabbsOffset, boxes);
        } else {
          std::vector<uint32_t> vertices = Vertices();
          const std::vector<uint32_t> more = Vertices(2.0f);
          vertices.insert(vertices.end(), more.begin(), more.begin() + 6);  // vertices 6 and 7
          rig.Write(cb, Component(0, 0), vertices);
          if (!c.indices.empty()) rig.Write(cb, Inputs::kIndicesOffset, c.indices);
        }
        rig.Build(cb, c.shape);
      }));
      CHECK(f.monitor().Verify() == "");
      rig.Run(rig.Record([&](VkCommandBuffer cb) {
        rig.Fill(cb, c.outside, kNan);
        rig.Update(cb, c.shape);
      }));
      CHECK(f.monitor().Verify() == "");
      rig.Run(rig.Record([&](VkCommandBuffer cb) {
        rig.Fill(cb, c.in_primitive_1, kNan);
        rig.Update(cb, c.shape);
      }));
      CHECK(OnlyFinding(f.monitor(), kBecameInactive, ": primitive 1") == "");
    }
  }
}

TEST_CASE("capture: each geometry of an update is compared with the same geometry of its source",
          "[integration][capture]") {
  // The helpers' geometries all read the same vertices: one NaN makes primitive 1 of each inactive.
  HistoryFixture f;
  Rig rig(f);
  Shape shape = Triangles();
  shape.geometries = 3;
  BuildTriangles(rig);  // writes the vertices (the build's shape is rebuilt below)
  rig.Run(rig.Record([&](VkCommandBuffer cb) { rig.Build(cb, shape); }));
  CHECK(f.monitor().Verify() == "");
  rig.Run(rig.Record([&](VkCommandBuffer cb) {
    rig.Fill(cb, Component(4, 0), kNan);
    rig.Update(cb, shape);
  }));
  const std::vector<Message> messages = f.monitor().Take();
  REQUIRE(messages.size() == 3);
  for (uint32_t j = 0; j < 3; ++j) {
    INFO(messages[j].text);
    CHECK(messages[j].id_name == kBecameInactive);
    CHECK(messages[j].text.find("geometry " + std::to_string(j) + ": 1 primitive(s)") != std::string::npos);
  }
}

TEST_CASE("capture: an update recorded in a secondary command buffer is judged when the primary executes",
          "[integration][capture]") {
  HistoryFixture f;
  Rig rig(f);
  BuildTriangles(rig);
  VkCommandBuffer secondary = rig.commands().BeginSecondary();
  rig.commands().Barrier(secondary);  // after any update before it
  rig.Fill(secondary, Component(4, 0), kNan);
  rig.Update(secondary, Triangles());
  rig.commands().End(secondary);
  const Procs procs(rig.device());
  rig.Run(rig.Record([&](VkCommandBuffer cb) { procs.CmdExecuteCommands(cb, 1, &secondary); }));
  CHECK(OnlyFinding(f.monitor(), kBecameInactive, ": primitive 1") == "");
}

TEST_CASE("capture valid twin: updates that keep each primitive's activity and the index values stay silent",
          "[integration][capture]") {
  HistoryFixture f;  // every family, default settings (capture=updates)
  Rig rig(f);
  Shape shape = Triangles();  // the shape of the section's last update

  SECTION("a refit that moves the vertices") {
    BuildTriangles(rig);
    rig.Run(rig.Record([&](VkCommandBuffer cb) {
      rig.Write(cb, Component(0, 0), Vertices(0.5f));
      rig.Update(cb, Triangles());
    }));
  }
  SECTION("a triangle made degenerate and back (active throughout)") {
    BuildTriangles(rig);
    const std::vector<uint32_t> vertices = Vertices();
    const std::vector<uint32_t> vertex3(vertices.begin() + 3 * 3, vertices.begin() + 4 * 3);
    rig.Run(rig.Record([&](VkCommandBuffer cb) {
      rig.Write(cb, Component(4, 0), vertex3);
      rig.Write(cb, Component(5, 0), vertex3);
      rig.Update(cb, Triangles());
    }));
    CHECK(f.monitor().Verify() == "");
    rig.Run(rig.Record([&](VkCommandBuffer cb) {
      rig.Write(cb, Component(0, 0), Vertices());
      rig.Update(cb, Triangles());
    }));
  }
  SECTION("an inactive triangle keeps a NaN X, of other bits or at another vertex, and gets NaN Y and Z") {
    std::vector<uint32_t> vertices = Vertices();
    vertices[3 * 3] = kNan;  // triangle 1 inactive in the build
    BuildTriangles(rig, vertices);
    rig.Run(rig.Record([&](VkCommandBuffer cb) {
      rig.Fill(cb, Component(3, 0), kOtherNan);
      rig.Fill(cb, Component(4, 1), kNan);
      rig.Fill(cb, Component(5, 2), kNan);
      rig.Update(cb, Triangles());
    }));
    CHECK(f.monitor().Verify() == "");
    rig.Run(rig.Record([&](VkCommandBuffer cb) {
      rig.Write(cb, Component(3, 0), {Bits(0.0f)});
      rig.Fill(cb, Component(5, 0), kNan);
      rig.Update(cb, Triangles());
    }));
  }
  SECTION("indexed triangles refitted with the same index values") {
    for (VkIndexType type : {VK_INDEX_TYPE_UINT32, VK_INDEX_TYPE_UINT16}) {
      rig.Run(rig.Record([&](VkCommandBuffer cb) {
        rig.Write(cb, Component(0, 0), Vertices());
        rig.Write(cb, Inputs::kIndicesOffset, Indices(type));
        rig.Build(cb, Indexed(type));
      }));
      rig.Run(rig.Record([&](VkCommandBuffer cb) {
        rig.Write(cb, Component(0, 0), Vertices(-0.5f));
        rig.Write(cb, Inputs::kIndicesOffset, Indices(type));  // rewritten, the same values
        rig.Update(cb, Indexed(type));
      }));
      shape = Indexed(type);
    }
  }
  SECTION("AABBs that move") {
    rig.Run(rig.Record([&](VkCommandBuffer cb) {
      rig.Write(cb, Inputs::kAabbsOffset, Boxes());
      rig.Build(cb, Aabbs());
    }));
    rig.Run(rig.Record([&](VkCommandBuffer cb) {
      rig.Write(cb, Inputs::kAabbsOffset, Boxes(4.0f));
      rig.Update(cb, Aabbs());
    }));
    shape = Aabbs();
  }
  SECTION("the update in the build's command buffer, after the app's barrier") {
    rig.Run(rig.Record([&](VkCommandBuffer cb) {
      rig.Write(cb, Component(0, 0), Vertices());
      rig.Build(cb, Triangles());
      rig.AfterBuild(cb);
      rig.Write(cb, Component(0, 0), Vertices(1.0f));
      rig.Update(cb, Triangles());
    }));
  }
  SECTION("a build-and-update command buffer submitted again after the first submission completed") {
    // The second execution's update is compared with the second execution's build, not the first's.
    std::vector<uint32_t> vertices = Vertices();
    vertices[3 * 3] = kNan;  // triangle 1 inactive in each execution's build
    VkCommandBuffer both = rig.Record([&](VkCommandBuffer cb) {
      rig.Write(cb, Component(0, 0), vertices);
      rig.Build(cb, Triangles());
      rig.AfterBuild(cb);
      rig.Update(cb, Triangles());
    });
    rig.Run(both);
    CHECK(f.monitor().Verify() == "");
    rig.Run(both, Wait::kFence);
  }
  SECTION("a secondary command buffer with a refit, executed twice by one primary") {
    // Each execution's capture is read from its own bytes (the first's saved before the second writes the slab).
    BuildTriangles(rig);
    VkCommandBuffer secondary = rig.commands().BeginSecondary(VK_COMMAND_BUFFER_USAGE_SIMULTANEOUS_USE_BIT);
    rig.commands().Barrier(secondary);
    rig.Write(secondary, Component(0, 0), Vertices(0.25f));
    rig.Update(secondary, Triangles());
    rig.commands().End(secondary);
    const Procs procs(rig.device());
    rig.Run(rig.Record([&](VkCommandBuffer cb) {
      procs.CmdExecuteCommands(cb, 1, &secondary);
      rig.AfterBuild(cb);
      procs.CmdExecuteCommands(cb, 1, &secondary);
    }));
    CHECK(f.monitor().Verify() == "");
  }
  SECTION("an update command buffer submitted again after the first submission completed") {
    BuildTriangles(rig);
    VkCommandBuffer update = rig.Record([&](VkCommandBuffer cb) {
      rig.Write(cb, Component(0, 0), Vertices(2.0f));
      rig.Update(cb, Triangles());
    });
    rig.Run(update);
    CHECK(f.monitor().Verify() == "");
    rig.Run(update, Wait::kFence);
  }
  CHECK(f.monitor().Verify() == "");
  CHECK(Probe(rig, f.monitor(), shape) == "");
}

// How many updates the layer judged on their captured activity, and whether any check was skipped for unknown state,
// as ASVAL-History-Summary (at vkDestroyDevice, in the JSON report) says.
struct Judged {
  uint64_t updates = 0;
  bool skipped_unknown = false;
};
Judged ReadJudged(const asval_test_common::TempReport& report) {
  Judged j;
  for (const std::string& line : report.Lines()) {
    const std::string judged = " updates judged on their captured activity";
    const std::size_t at = line.find(judged);
    if (at != std::string::npos) {
      const std::size_t start = line.rfind(", ", at) + 2;
      j.updates = std::stoull(line.substr(start, at - start));
    }
    j.skipped_unknown |= line.find("checks were skipped because the state they need was unknown") != std::string::npos;
  }
  return j;
}

// Issue 25, item 5: a SIMULTANEOUS_USE secondary holding an update, executed twice by one primary, with the update's
// input rewritten on the device between the two executions. Each execution's update is judged on the bytes it read:
// the second one's against the first one's (the source's last executed build). Before, both shared one capture
// slot and were skipped as unknown. Triangle 1 is inactive in the build (a NaN X); between the executions its X is
// written 0 (active: pInfos-03663 on the second execution) or another NaN (still inactive: the valid twin, whose
// two updates must be judged, not skipped). Between the executions: an update of the primary's own (vkCmdFillBuffer
// in the primary), or a third secondary doing the fill, with all three in one vkCmdExecuteCommands.
TEST_CASE("capture: a secondary executed twice by one primary: each execution's update is judged on its own bytes",
          "[integration][capture]") {
  for (const bool one_call : {false, true}) {
    for (const bool activates : {true, false}) {
      DYNAMIC_SECTION((one_call ? "one vkCmdExecuteCommands of three" : "two vkCmdExecuteCommands")
                      << (activates ? ": triangle 1 made active (pInfos-03663)" : ": valid twin")) {
        asval_test_common::TempReport report;
        {
          HistoryFixture f(nullptr, {{"report_file", report.path.c_str()}, {"report_flags", "error,warn,info"}});
          {
            Rig rig(f);
            std::vector<uint32_t> vertices = Vertices();
            vertices[3 * 3] = kNan;  // triangle 1 inactive in the build
            BuildTriangles(rig, vertices);
            VkCommandBuffer refit = rig.commands().BeginSecondary(VK_COMMAND_BUFFER_USAGE_SIMULTANEOUS_USE_BIT);
            rig.commands().Barrier(refit);  // after the build, or the first execution's update
            rig.Update(refit, Triangles());
            rig.commands().End(refit);
            // Triangle 1's first X, rewritten once the first execution's update has read it.
            const auto rewrite = [&](VkCommandBuffer cb) {
              rig.AfterBuild(cb);
              if (activates) {
                rig.Write(cb, Component(3, 0), {Bits(0.0f)});
              } else {
                rig.Fill(cb, Component(3, 0), kOtherNan);
              }
            };
            const Procs procs(rig.device());
            if (one_call) {
              VkCommandBuffer write = rig.commands().BeginSecondary();
              rewrite(write);
              rig.commands().End(write);
              const VkCommandBuffer three[] = {refit, write, refit};
              rig.Run(rig.Record([&](VkCommandBuffer cb) { procs.CmdExecuteCommands(cb, 3, three); }), Wait::kFence);
            } else {
              rig.Run(rig.Record([&](VkCommandBuffer cb) {
                procs.CmdExecuteCommands(cb, 1, &refit);
                rewrite(cb);
                procs.CmdExecuteCommands(cb, 1, &refit);
              }),
                      Wait::kFence);
            }
            if (activates) {
              CHECK(OnlyFinding(f.monitor(), kBecameActive, "geometry 0: 1 primitive(s) inactive in the source are "
                                                            "active in the update: primitive 1") == "");
            } else {
              CHECK(f.monitor().Verify() == "");
            }
          }
          f.Close();
        }
        const Judged judged = ReadJudged(report);
        CHECK(judged.updates == 2);  // both executions' updates, none skipped
        CHECK_FALSE(judged.skipped_unknown);
      }
    }
  }
}

// The limit (capture.md, "Executed more than once"): a SIMULTANEOUS_USE primary listed twice in one batch writes its
// captures twice before the host reads them, and nothing between its executions is the layer's. Its second update
// would make triangle 1 active (the batch rewrites its X between them); both updates are skipped and counted, never
// judged on bytes the second execution overwrote.
TEST_CASE("capture: a primary listed twice in one batch: its updates are skipped and counted, never guessed",
          "[integration][capture]") {
  asval_test_common::TempReport report;
  {
    HistoryFixture f(nullptr, {{"report_file", report.path.c_str()}, {"report_flags", "error,warn,info"}});
    {
      Rig rig(f);
      std::vector<uint32_t> vertices = Vertices();
      vertices[3 * 3] = kNan;  // triangle 1 inactive in the build
      BuildTriangles(rig, vertices);
      VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
      alloc.commandPool = rig.commands().pool();
      alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
      alloc.commandBufferCount = 1;
      VkCommandBuffer refit = VK_NULL_HANDLE;
      REQUIRE(vkAllocateCommandBuffers(rig.device().handle(), &alloc, &refit) == VK_SUCCESS);
      VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
      begin.flags = VK_COMMAND_BUFFER_USAGE_SIMULTANEOUS_USE_BIT;
      REQUIRE(vkBeginCommandBuffer(refit, &begin) == VK_SUCCESS);
      rig.commands().Barrier(refit);
      rig.Update(refit, Triangles());
      REQUIRE(vkEndCommandBuffer(refit) == VK_SUCCESS);
      const VkCommandBuffer rewrite = rig.Record([&](VkCommandBuffer cb) {
        rig.AfterBuild(cb);
        rig.Write(cb, Component(3, 0), {Bits(0.0f)});
      });
      CHECK(rig.commands().Submit({refit, rewrite, refit}) == VK_SUCCESS);  // waits for the queue
      CHECK(f.monitor().Verify() == "");
    }
    f.Close();
  }
  const Judged judged = ReadJudged(report);
  CHECK(judged.updates == 0);
  CHECK(judged.skipped_unknown);
}

TEST_CASE("capture: with capture=off, an update that makes a triangle inactive is not reported",
          "[integration][capture]") {
  HistoryFixture f(nullptr, {{"capture", "off"}});
  Rig rig(f);
  BuildTriangles(rig);
  rig.Run(rig.Record([&](VkCommandBuffer cb) {
    rig.Fill(cb, Component(4, 0), kNan);
    rig.Update(cb, Triangles());
  }));
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("capture: with capture=all, an update that makes a triangle inactive is reported as by default",
          "[integration][capture]") {
  // `all` captures builds without ALLOW_UPDATE too; what an update is compared with is the same.
  HistoryFixture f(nullptr, {{"capture", "all"}});
  Rig rig(f);
  Shape fixed = Triangles();
  fixed.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
  rig.Run(rig.Record([&](VkCommandBuffer cb) { rig.other().Build(cb, fixed); }));  // captured, never updated
  BuildTriangles(rig);
  CHECK(f.monitor().Verify() == "");
  rig.Run(rig.Record([&](VkCommandBuffer cb) {
    rig.Fill(cb, Component(4, 0), kNan);
    rig.Update(cb, Triangles());
  }));
  CHECK(OnlyFinding(f.monitor(), kBecameInactive, ": primitive 1") == "");
}

TEST_CASE("capture: a build that reads a NaN Y with X not NaN gets the undefined-input warning",
          "[integration][capture]") {
  // Y of triangle 1's second vertex is NaN, its X is not: the specification leaves the build's result undefined
  // (a warning of the layer's own, ASVAL-Capture-UndefinedInput), and the triangle stays active.
  HistoryFixture f;
  Rig rig(f);
  rig.Run(rig.Record([&](VkCommandBuffer cb) {
    std::vector<uint32_t> vertices = Vertices();
    vertices[3 * 4 + 1] = kNan;
    rig.Write(cb, Component(0, 0), vertices);
    rig.Build(cb, Triangles());
  }));
  CHECK(OnlyFinding(f.monitor(), "ASVAL-Capture-UndefinedInput", "geometry 0: 1 primitive(s)") == "");
  // The twin: the same NaN Y on a triangle whose X is NaN too (inactive: nothing undefined) stays silent.
  rig.Run(rig.Record([&](VkCommandBuffer cb) {
    std::vector<uint32_t> vertices = Vertices();
    vertices[3 * 4 + 0] = kNan;
    vertices[3 * 4 + 1] = kNan;
    rig.Write(cb, Component(0, 0), vertices);
    rig.Build(cb, Triangles());
  }));
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("capture: a triangle geometry whose transform holds an infinity gets the non-finite-transform warning",
          "[integration][capture]") {
  // ASVAL-Capture-NonFiniteTransform: the transform's translation Y is written as +infinity on the device before
  // the build. The twin: the helpers' identity transform stays silent.
  HistoryFixture f;
  Rig rig(f);
  Shape shape = Triangles();
  shape.transform = true;
  rig.Run(rig.Record([&](VkCommandBuffer cb) {
    rig.Write(cb, Component(0, 0), Vertices());
    rig.Build(cb, shape);
  }));
  CHECK(f.monitor().Verify() == "");
  rig.Run(rig.Record([&](VkCommandBuffer cb) {
    rig.Write(cb, Inputs::kTransformOffset + 4 * 7, {0x7f800000u});  // matrix[1][3] = +inf
    rig.Build(cb, shape);
  }));
  CHECK(OnlyFinding(f.monitor(), "ASVAL-Capture-NonFiniteTransform", "geometry 0: its transform") == "");
}

// Protect mode (issue 16, docs/protect.md) and a rule judged at completion: the update that broke it already ran,
// so every later submission on the device is withheld, each named in an ASVAL-Protect-Withheld line of the report.
std::vector<std::string> ProtectLines(const asval_test_common::TempReport& report) {
  std::vector<std::string> out;
  for (const std::string& line : report.Lines()) {
    if (line.find("\"vuid\":\"ASVAL-Protect-Withheld\"") != std::string::npos ||
        line.find("Protect mode kept from the driver") != std::string::npos) {
      out.push_back(line);
    }
  }
  return out;
}

TEST_CASE("capture: with protect on, an error judged at completion withholds every later submission",
          "[integration][capture][protect]") {
  asval_test_common::TempReport report;
  HistoryFixture f(nullptr, {{"protect", "true"}, {"report_file", report.path.c_str()}});
  {
    Rig rig(f);
    BuildTriangles(rig);
    rig.Run(rig.Record([&](VkCommandBuffer cb) {
      rig.Fill(cb, Component(0, 0), kNan);
      rig.Update(cb, Triangles());
    }));
    CHECK(OnlyFinding(f.monitor(), kBecameInactive, ": primitive 0") == "");
    // A valid rebuild, on a queue whose device ran a rule-breaking update: withheld.
    const VkCommandBuffer rebuild = rig.Record([&](VkCommandBuffer cb) { rig.Build(cb, Triangles()); });
    CHECK(rig.commands().Submit(rebuild) == VK_ERROR_VALIDATION_FAILED_EXT);
    CHECK(rig.commands().Submit(rebuild) == VK_ERROR_VALIDATION_FAILED_EXT);
    CHECK(f.monitor().Verify() == "");
  }
  f.Close();
  const std::vector<std::string> lines = ProtectLines(report);
  REQUIRE(lines.size() == 4);
  CHECK(lines[0].find("\"function\":\"vkCmdBuildAccelerationStructuresKHR\"") != std::string::npos);
  CHECK(lines[0].find(std::string("asval reported ") + kBecameInactive) != std::string::npos);
  CHECK(lines[0].find("Every later submission on this device is withheld") != std::string::npos);
  for (int i : {1, 2}) {
    CHECK(lines[i].find("\"function\":\"vkQueueSubmit\"") != std::string::npos);
    CHECK(lines[i].find(std::string("found when it completed: ") + kBecameInactive) != std::string::npos);
  }
  CHECK(lines[3].find("recorded_commands_withheld=0 submissions_withheld=2 host_commands_withheld=0 "
                      "submissions_halted_by_completion_error=1") != std::string::npos);
}

TEST_CASE("capture: with protect on, updates judged valid at completion leave later submissions alone",
          "[integration][capture][protect]") {
  asval_test_common::TempReport report;
  HistoryFixture f(nullptr, {{"protect", "true"}, {"report_file", report.path.c_str()}});
  {
    Rig rig(f);
    BuildTriangles(rig);
    // The same update with the vertices moved (activity unchanged): judged, and valid.
    rig.Run(rig.Record([&](VkCommandBuffer cb) {
      rig.Write(cb, Component(0, 0), Vertices(0.5f));
      rig.Update(cb, Triangles());
    }));
    const VkCommandBuffer rebuild = rig.Record([&](VkCommandBuffer cb) { rig.Build(cb, Triangles()); });
    CHECK(rig.commands().Submit(rebuild) == VK_SUCCESS);
    CHECK(f.monitor().Verify() == "");
    // The updates were judged: the probe's activity change is still found (and halts what follows).
    CHECK(Probe(rig, f.monitor(), Triangles()) == "");
  }
  f.Close();
  CHECK(ProtectLines(report).size() == 2);  // the probe's halt and the summary; nothing before it
}

}  // namespace
}  // namespace asval_test
