// Family "history", the rules decided on the bytes a build reads when it EXECUTES: an update may not change which
// primitives are active (pInfos-03663, 03664) nor the index values (pInfos-03768) of its source's last build, and a
// top-level build's instances may reference only live structures (pInfos-06707). The data is written the way
// programs write it: on the host into mapped buffers after the command buffer was recorded, or on the device by
// vkCmdCopyBuffer / vkCmdUpdateBuffer in front of the refit, so that the fault exists only in the bytes at execution
// time (what the buffers held when the command was recorded, or submitted, is valid). Every case waits for its
// submissions: that is when the bytes are known.
//
// A triangle is inactive when the X of one of its vertices is NaN, an AABB when its minimum X is NaN, an instance
// when its accelerationStructureReference is 0. A "destroyed" bottom-level structure is one whose handle was
// destroyed while the buffer it lived in (a pool) stays: lavapipe reads the referenced structures when it builds,
// so the stale address always names allocated bytes.
#include <cstddef>
#include <cstring>
#include <limits>
#include <vector>

#include "capture_helpers.h"
#include "corpus.h"
#include "history_helpers.h"

namespace {

using asval_test::Blas;
using asval_test::Commands;
using asval_test::Inputs;
using asval_test::Shape;
using asval_test::Tlas;

constexpr auto kBuild = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
constexpr auto kUpdate = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
constexpr VkBufferUsageFlags kInputUsage =
    VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
constexpr float kNan = std::numeric_limits<float>::quiet_NaN();
constexpr VkDeviceSize kInstanceBytes = sizeof(VkAccelerationStructureInstanceKHR);
constexpr VkDeviceSize kReferenceOffset = offsetof(VkAccelerationStructureInstanceKHR, accelerationStructureReference);

// Six vertices (two unit right triangles at z = 0 and z = 1), moved by dx along X: what a simulation writes.
std::vector<float> Positions(float dx) {
  const float corner[3][2] = {{0, 0}, {1, 0}, {0, 1}};
  std::vector<float> xyz;
  for (uint32_t v = 0; v < 6; ++v) {
    xyz.push_back(corner[v % 3][0] + dx);
    xyz.push_back(corner[v % 3][1]);
    xyz.push_back(static_cast<float>(v / 3));
  }
  return xyz;
}

Shape TwoTriangles(VkIndexType index_type = VK_INDEX_TYPE_NONE_KHR) {
  Shape s;
  s.triangles = 2;
  s.index_type = index_type;
  return s;
}

Shape TwoBoxes() {
  Shape s = TwoTriangles();
  s.geometry_type = VK_GEOMETRY_TYPE_AABBS_KHR;
  return s;
}

// A host-visible staging buffer the app fills on the host and copies from on the device.
struct Staging {
  Staging(vkkit::Device& d, VkDeviceSize size) : device(d) {
    buffer = device.CreateBuffer(size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  }
  ~Staging() { device.Destroy(buffer); }
  template <typename T>
  void Fill(const std::vector<T>& values) {
    std::memcpy(buffer.mapped, values.data(), values.size() * sizeof(T));
  }
  // vkCmdCopyBuffer of `size` bytes from the start of the staging buffer to `offset` of `dst`.
  void CopyTo(VkCommandBuffer cb, VkBuffer dst, VkDeviceSize offset, VkDeviceSize size) const {
    const VkBufferCopy region{0, offset, size};
    vkCmdCopyBuffer(cb, buffer.buffer, dst, 1, &region);
  }
  vkkit::Device& device;
  vkkit::Buffer buffer;
};

// The mapped inputs, written on the host (the vertices of Positions(0) are already there).
void HostWriteFloat(const Inputs& inputs, VkDeviceSize offset, float value) {
  std::memcpy(static_cast<unsigned char*>(inputs.buffer().mapped) + offset, &value, sizeof value);
}

// Byte offset of component c of vertex v in the inputs (R32G32B32_SFLOAT, tightly packed).
VkDeviceSize Component(uint32_t v, uint32_t c) { return Inputs::kVerticesOffset + 12 * v + 4 * c; }

// One frame's refit: the staging bytes copied over the inputs at `offset`, made visible to the build, the refit.
void CopyAndRefit(vkkit::Device& device, Blas& blas, const Inputs& inputs, const Staging& staging, VkDeviceSize offset,
                  VkDeviceSize size, const Shape& shape) {
  device.OneShot([&](VkCommandBuffer cb) {
    staging.CopyTo(cb, inputs.buffer().buffer, offset, size);
    asval_test::InputsWritten(cb);
    blas.Update(cb, shape);
  });
}

// ---- bottom-level refits -------------------------------------------------------------------------------------

CORPUS_CASE(RefitCopyMakesTriangleInactive, "capture-refit-copy-makes-triangle-inactive", "history",
            "a deforming BLAS refitted every frame from positions copied by vkCmdCopyBuffer; in frame 3 the simulation "
            "culls a triangle with a NaN X, which the BLAS build had active",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03664"}) {
  Inputs inputs(device, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  Blas blas(device, inputs);
  device.OneShot([&](VkCommandBuffer cb) { blas.Build(cb, TwoTriangles()); });
  Staging staging(device, 6 * 12);
  for (int frame = 1; frame <= 3; ++frame) {
    std::vector<float> positions = Positions(0.25f * frame);
    if (frame == 3) positions[3 * 4] = kNan;  // triangle 1's second vertex
    staging.Fill(positions);
    CopyAndRefit(device, blas, inputs, staging, Inputs::kVerticesOffset, 6 * 12, TwoTriangles());
  }
}

CORPUS_CASE(RefitCopyMovesVertices, "capture-refit-copy-moves-vertices", "history",
            "a deforming BLAS refitted every frame from positions copied by vkCmdCopyBuffer, every triangle active "
            "throughout",
            {}) {
  Inputs inputs(device, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  Blas blas(device, inputs);
  device.OneShot([&](VkCommandBuffer cb) { blas.Build(cb, TwoTriangles()); });
  Staging staging(device, 6 * 12);
  for (int frame = 1; frame <= 4; ++frame) {
    staging.Fill(Positions(0.25f * frame));
    CopyAndRefit(device, blas, inputs, staging, Inputs::kVerticesOffset, 6 * 12, TwoTriangles());
  }
}

CORPUS_CASE(RefitUpdateBufferRevivesTriangle, "capture-refit-update-buffer-revives-triangle", "history",
            "a BLAS built with triangle 1 inactive (NaN X written on the host); a vkCmdUpdateBuffer in front of the "
            "refit writes a finite X there",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03663"}) {
  Inputs inputs(device, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  Blas blas(device, inputs);
  HostWriteFloat(inputs, Component(3, 0), kNan);
  device.OneShot([&](VkCommandBuffer cb) { blas.Build(cb, TwoTriangles()); });
  device.OneShot([&](VkCommandBuffer cb) {
    const float x = 0.0f;
    vkCmdUpdateBuffer(cb, inputs.buffer().buffer, Component(3, 0), sizeof x, &x);
    asval_test::InputsWritten(cb);
    blas.Update(cb, TwoTriangles());
  });
}

CORPUS_CASE(InactiveTriangleStaysInactive, "capture-inactive-triangle-stays-inactive", "history",
            "a BLAS built with triangle 1 inactive; every frame's copied positions move the active triangle and keep "
            "a NaN X (another vertex, another NaN) in triangle 1",
            {}) {
  Inputs inputs(device, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  Blas blas(device, inputs);
  HostWriteFloat(inputs, Component(3, 0), kNan);
  device.OneShot([&](VkCommandBuffer cb) { blas.Build(cb, TwoTriangles()); });
  Staging staging(device, 6 * 12);
  for (int frame = 1; frame <= 3; ++frame) {
    std::vector<float> positions = Positions(0.5f * frame);
    positions[3 * (3 + frame % 3)] = frame % 2 ? -kNan : kNan;
    staging.Fill(positions);
    CopyAndRefit(device, blas, inputs, staging, Inputs::kVerticesOffset, 6 * 12, TwoTriangles());
  }
}

CORPUS_CASE(HiddenTriangleAllNan, "capture-hidden-triangle-all-nan-positions", "history",
            "a skinning pass hides triangle 1 by writing (NaN, NaN, NaN) to all its vertices before the build and "
            "every refit (vkCmdCopyBuffer), while triangle 0 moves",
            {}) {
  Inputs inputs(device, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  Blas blas(device, inputs);
  Staging staging(device, 6 * 12);
  for (int frame = 0; frame <= 3; ++frame) {
    std::vector<float> positions = Positions(0.25f * frame);
    for (size_t i = 3 * 3; i < positions.size(); ++i) positions[i] = kNan;
    staging.Fill(positions);
    device.OneShot([&](VkCommandBuffer cb) {
      staging.CopyTo(cb, inputs.buffer().buffer, Inputs::kVerticesOffset, 6 * 12);
      asval_test::InputsWritten(cb);
      if (frame == 0) {
        blas.Build(cb, TwoTriangles());
      } else {
        blas.Update(cb, TwoTriangles());
      }
    });
  }
}

CORPUS_CASE(DegenerateTriangleStaysActive, "capture-degenerate-triangle-stays-active", "history",
            "a refit whose copied positions collapse triangle 1 to a point (degenerate, still active), and the next "
            "refit restores it",
            {}) {
  Inputs inputs(device, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  Blas blas(device, inputs);
  device.OneShot([&](VkCommandBuffer cb) { blas.Build(cb, TwoTriangles()); });
  Staging staging(device, 6 * 12);
  std::vector<float> collapsed = Positions(0);
  for (uint32_t v = 4; v < 6; ++v) {
    for (uint32_t c = 0; c < 3; ++c) collapsed[3 * v + c] = collapsed[3 * 3 + c];
  }
  staging.Fill(collapsed);
  CopyAndRefit(device, blas, inputs, staging, Inputs::kVerticesOffset, 6 * 12, TwoTriangles());
  staging.Fill(Positions(0));
  CopyAndRefit(device, blas, inputs, staging, Inputs::kVerticesOffset, 6 * 12, TwoTriangles());
}

CORPUS_CASE(ResubmittedRefitHostNan, "capture-resubmitted-refit-host-writes-nan", "history",
            "one refit command buffer recorded once and resubmitted every frame after the host writes new positions "
            "into the mapped vertex buffer; frame 3's positions hold a NaN X in triangle 0",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03664"}) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  device.OneShot([&](VkCommandBuffer cb) { blas.Build(cb, TwoTriangles()); });
  VkCommandBuffer refit = commands.Begin();
  blas.Update(refit, TwoTriangles());
  commands.End(refit);
  for (int frame = 1; frame <= 3; ++frame) {
    std::vector<float> positions = Positions(0.25f * frame);
    if (frame == 3) positions[3 * 1] = kNan;
    std::memcpy(inputs.buffer().mapped, positions.data(), positions.size() * sizeof(float));
    commands.Submit(refit);
  }
}

// Programs learn of completion in several ways; each is where the bytes a refit read become known.
void CopyNanAndRefitThenWait(vkkit::Device& device, asval_test::Wait wait, bool nan) {
  Inputs inputs(device, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  Blas blas(device, inputs);
  Commands commands(device);
  device.OneShot([&](VkCommandBuffer cb) { blas.Build(cb, TwoTriangles()); });
  Staging staging(device, 6 * 12);
  std::vector<float> positions = Positions(0.75f);
  if (nan) positions[3 * 0] = kNan;
  staging.Fill(positions);
  VkCommandBuffer refit = asval_test::RecordWith(commands, [&](VkCommandBuffer cb) {
    staging.CopyTo(cb, inputs.buffer().buffer, Inputs::kVerticesOffset, 6 * 12);
    asval_test::InputsWritten(cb);
    blas.Update(cb, TwoTriangles());
  });
  asval_test::SubmitAndWait(device, refit, wait);
}

CORPUS_CASE(RefitNanFenceWait, "capture-refit-copy-nan-waited-by-fence", "history",
            "a refit after a vkCmdCopyBuffer of positions with a NaN X in triangle 0, the submission waited for with "
            "vkWaitForFences",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03664"}) {
  CopyNanAndRefitThenWait(device, asval_test::Wait::kFence, true);
}

CORPUS_CASE(RefitNanDeviceIdle, "capture-refit-copy-nan-waited-by-device-idle", "history",
            "a refit after a vkCmdCopyBuffer of positions with a NaN X in triangle 0, the submission waited for with "
            "vkDeviceWaitIdle",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03664"}) {
  CopyNanAndRefitThenWait(device, asval_test::Wait::kDeviceIdle, true);
}

CORPUS_CASE(RefitFencePolled, "capture-refit-copy-waited-by-fence-polling", "history",
            "a refit after a vkCmdCopyBuffer of moved positions, the submission's fence polled with vkGetFenceStatus",
            {}) {
  CopyNanAndRefitThenWait(device, asval_test::Wait::kFenceStatus, false);
}

CORPUS_CASE(RefitRecordedFirstInFlight, "capture-refit-recorded-first-both-in-flight", "history",
            "a refit command buffer (copy of positions with a NaN X in triangle 1, then the refit) recorded before the "
            "build's; both submitted without a wait in between, build first, then one vkQueueWaitIdle",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03664"}) {
  Inputs inputs(device, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  Blas blas(device, inputs);
  Commands commands(device);
  Staging staging(device, 6 * 12);
  std::vector<float> positions = Positions(0.5f);
  positions[3 * 3] = kNan;
  staging.Fill(positions);
  VkCommandBuffer refit = asval_test::RecordWith(commands, [&](VkCommandBuffer cb) {
    // The build of the earlier submission wrote the structure and read the vertices this copy overwrites.
    commands.Barrier(cb);
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
                         0, nullptr, 0, nullptr, 0, nullptr);
    staging.CopyTo(cb, inputs.buffer().buffer, Inputs::kVerticesOffset, 6 * 12);
    asval_test::InputsWritten(cb);
    blas.Update(cb, TwoTriangles());
  });
  VkCommandBuffer build = asval_test::RecordWith(commands, [&](VkCommandBuffer cb) { blas.Build(cb, TwoTriangles()); });
  for (VkCommandBuffer cb : {build, refit}) {
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cb;
    vkkit::Check(vkQueueSubmit(device.queue(), 1, &submit, VK_NULL_HANDLE), "vkQueueSubmit");
  }
  vkkit::Check(vkQueueWaitIdle(device.queue()), "vkQueueWaitIdle");
}

CORPUS_CASE(RefitUint16IndicesChanged, "capture-refit-update-buffer-changes-uint16-indices", "history",
            "a BLAS with UINT16 indices written on the host; a vkCmdUpdateBuffer in front of the refit makes triangle "
            "1 (3, 4, 5) into (3, 4, 0)",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03768"}) {
  Inputs inputs(device, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  Blas blas(device, inputs);
  const std::vector<uint16_t> indices = {0, 1, 2, 3, 4, 5};
  std::memcpy(static_cast<unsigned char*>(inputs.buffer().mapped) + Inputs::kIndicesOffset, indices.data(),
              indices.size() * sizeof(uint16_t));
  device.OneShot([&](VkCommandBuffer cb) { blas.Build(cb, TwoTriangles(VK_INDEX_TYPE_UINT16)); });
  device.OneShot([&](VkCommandBuffer cb) {
    const uint16_t last_pair[2] = {4, 0};  // indices 4 and 5 (a 4-byte aligned update)
    vkCmdUpdateBuffer(cb, inputs.buffer().buffer, Inputs::kIndicesOffset + 4 * 2, sizeof last_pair, last_pair);
    asval_test::InputsWritten(cb);
    blas.Update(cb, TwoTriangles(VK_INDEX_TYPE_UINT16));
  });
}

CORPUS_CASE(RefitCopyChangesIndices, "capture-refit-copy-changes-indices", "history",
            "an indexed BLAS (UINT32) refitted after a vkCmdCopyBuffer that rewrites its index buffer with other "
            "values (triangle 0 becomes 0, 1, 3)",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03768"}) {
  Inputs inputs(device, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  Blas blas(device, inputs);
  device.OneShot([&](VkCommandBuffer cb) { blas.Build(cb, TwoTriangles(VK_INDEX_TYPE_UINT32)); });
  Staging staging(device, 6 * 4);
  staging.Fill(std::vector<uint32_t>{0, 1, 3, 3, 4, 5});
  CopyAndRefit(device, blas, inputs, staging, Inputs::kIndicesOffset, 6 * 4, TwoTriangles(VK_INDEX_TYPE_UINT32));
}

CORPUS_CASE(RefitCopySameIndices, "capture-refit-rewrites-same-indices", "history",
            "an indexed BLAS (UINT16) whose index and vertex buffers are both rewritten by copies before each refit: "
            "the index values stay the same",
            {}) {
  Inputs inputs(device, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  Blas blas(device, inputs);
  const std::vector<uint16_t> indices = {0, 1, 2, 3, 4, 5};
  std::memcpy(static_cast<unsigned char*>(inputs.buffer().mapped) + Inputs::kIndicesOffset, indices.data(),
              indices.size() * sizeof(uint16_t));
  device.OneShot([&](VkCommandBuffer cb) { blas.Build(cb, TwoTriangles(VK_INDEX_TYPE_UINT16)); });
  Staging index_staging(device, 6 * 2);
  index_staging.Fill(indices);
  Staging vertex_staging(device, 6 * 12);
  for (int frame = 1; frame <= 2; ++frame) {
    vertex_staging.Fill(Positions(-0.5f * frame));
    device.OneShot([&](VkCommandBuffer cb) {
      index_staging.CopyTo(cb, inputs.buffer().buffer, Inputs::kIndicesOffset, 6 * 2);
      vertex_staging.CopyTo(cb, inputs.buffer().buffer, Inputs::kVerticesOffset, 6 * 12);
      asval_test::InputsWritten(cb);
      blas.Update(cb, TwoTriangles(VK_INDEX_TYPE_UINT16));
    });
  }
}

CORPUS_CASE(AabbRefitCopyNan, "capture-aabb-refit-copy-makes-box-inactive", "history",
            "a procedural (AABB) BLAS refitted from boxes copied by vkCmdCopyBuffer; the copied boxes give box 1 a "
            "NaN minimum X",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03664"}) {
  Inputs inputs(device, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  Blas blas(device, inputs);
  device.OneShot([&](VkCommandBuffer cb) { blas.Build(cb, TwoBoxes()); });
  Staging staging(device, 2 * 24);
  staging.Fill(std::vector<float>{0.5f, 0, 0, 1.5f, 1, 1, kNan, 0, 0, 3.5f, 1, 1});
  CopyAndRefit(device, blas, inputs, staging, Inputs::kAabbsOffset, 2 * 24, TwoBoxes());
}

CORPUS_CASE(RefitInSecondaryCopyNan, "capture-refit-in-secondary-copy-makes-triangle-inactive", "history",
            "a secondary command buffer copies the frame's positions (with a NaN X in triangle 0) and refits the BLAS; "
            "a primary executes it",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03664"}) {
  Inputs inputs(device, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  Blas blas(device, inputs);
  Commands commands(device);
  device.OneShot([&](VkCommandBuffer cb) { blas.Build(cb, TwoTriangles()); });
  Staging staging(device, 6 * 12);
  std::vector<float> positions = Positions(0.5f);
  positions[3 * 2] = kNan;
  staging.Fill(positions);
  VkCommandBuffer secondary = commands.BeginSecondary();
  staging.CopyTo(secondary, inputs.buffer().buffer, Inputs::kVerticesOffset, 6 * 12);
  asval_test::InputsWritten(secondary);
  blas.Update(secondary, TwoTriangles());
  commands.End(secondary);
  VkCommandBuffer primary = commands.Begin();
  vkCmdExecuteCommands(primary, 1, &secondary);
  commands.End(primary);
  commands.Submit(primary);
}

// In one command buffer: the build, the barriers that let the next copy overwrite what the build read and the refit
// read what the build wrote, the copy of the next positions, the refit.
void BuildCopyRefit(vkkit::Device& device, const std::vector<float>& next) {
  Inputs inputs(device, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  Blas blas(device, inputs);
  Commands commands(device);
  Staging staging(device, 6 * 12);
  staging.Fill(next);
  device.OneShot([&](VkCommandBuffer cb) {
    blas.Build(cb, TwoTriangles());
    commands.Barrier(cb);
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
                         0, nullptr, 0, nullptr, 0, nullptr);
    staging.CopyTo(cb, inputs.buffer().buffer, Inputs::kVerticesOffset, 6 * 12);
    asval_test::InputsWritten(cb);
    blas.Update(cb, TwoTriangles());
  });
}

CORPUS_CASE(BuildAndRefitOneCommandBufferNan, "capture-build-and-refit-in-one-command-buffer-nan", "history",
            "one command buffer builds the BLAS, copies new positions over its vertices (a NaN X in triangle 1) and "
            "refits it: the build and the refit read different bytes",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03664"}) {
  std::vector<float> next = Positions(1.0f);
  next[3 * 5] = kNan;
  BuildCopyRefit(device, next);
}

CORPUS_CASE(BuildAndRefitOneCommandBuffer, "capture-build-and-refit-in-one-command-buffer", "history",
            "one command buffer builds the BLAS, copies moved positions over its vertices and refits it", {}) {
  BuildCopyRefit(device, Positions(1.0f));
}

CORPUS_CASE(RefitIntoOtherNan, "capture-refit-into-another-structure-nan", "history",
            "a refit from BLAS a into BLAS b after a vkCmdUpdateBuffer wrote a NaN X into a vertex of triangle 1, "
            "active in a's build",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03664"}) {
  Inputs inputs(device, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  Blas a(device, inputs), b(device, inputs);
  device.OneShot([&](VkCommandBuffer cb) { a.Build(cb, TwoTriangles()); });
  device.OneShot([&](VkCommandBuffer cb) {
    vkCmdUpdateBuffer(cb, inputs.buffer().buffer, Component(4, 0), sizeof kNan, &kNan);
    asval_test::InputsWritten(cb);
    b.Update(cb, TwoTriangles(), &a);
  });
}

// A BLAS of one triangle (maxVertex with room for two), serialized into device memory of the size read back,
// deserialized into another structure; `refit` then refits that copy.
void SerializeDeserializeRefit(vkkit::Device& device, const Shape& refit) {
  Inputs inputs(device);
  Blas original(device, inputs), restored(device, inputs);
  Commands commands(device);
  Shape built;
  built.max_vertex = 5;
  asval_test::QueryPool pool(device, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR, 1);
  device.OneShot([&](VkCommandBuffer cb) {
    pool.Reset(cb);
    original.Build(cb, built);
    commands.Barrier(cb);
    asval_test::CmdWriteProperties(device, cb, {original.handle()},
                                   VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR, pool.handle(), 0);
  });
  vkkit::Buffer blob = device.CreateBuffer(pool.Results()[0], VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                                                  VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  device.OneShot([&](VkCommandBuffer cb) { asval_test::CmdSerialize(device, cb, original.handle(), blob.address); });
  device.OneShot([&](VkCommandBuffer cb) { asval_test::CmdDeserialize(device, cb, blob.address, restored.handle()); });
  VkCommandBuffer update = commands.Begin();
  restored.Update(update, refit);
  commands.End(update);
  commands.Submit(update);
  device.Destroy(blob);
}

CORPUS_CASE(DeserializedRefitMorePrimitives, "capture-deserialized-copy-refit-more-primitives", "history",
            "a 1-triangle BLAS serialized to device memory and deserialized into another structure (a cache round "
            "trip); the copy is refitted with 2 triangles",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-primitiveCount-03769"}) {
  Shape two;
  two.max_vertex = 5;
  two.triangles = 2;
  SerializeDeserializeRefit(device, two);
}

CORPUS_CASE(DeserializedRefit, "capture-deserialized-copy-refit", "history",
            "a 1-triangle BLAS serialized to device memory and deserialized into another structure; the copy is "
            "refitted with the original's parameters",
            {}) {
  Shape one;
  one.max_vertex = 5;
  SerializeDeserializeRefit(device, one);
}

// ---- top-level builds and updates ----------------------------------------------------------------------------

VkAccelerationStructureInstanceKHR Instance(VkDeviceAddress reference, uint32_t i, float dx = 0) {
  VkAccelerationStructureInstanceKHR instance{};
  instance.transform.matrix[0][0] = instance.transform.matrix[1][1] = instance.transform.matrix[2][2] = 1.0f;
  instance.transform.matrix[0][3] = static_cast<float>(i) * 4.0f + dx;
  instance.mask = 0xff;
  instance.accelerationStructureReference = reference;
  return instance;
}

// Two built BLASes, a TLAS and its instance buffer (host-mapped, also a transfer destination).
struct Scene {
  explicit Scene(vkkit::Device& d) : device(d), inputs(d), a(d, inputs), b(d, inputs), tlas(d) {
    instances = device.CreateBuffer(4 * kInstanceBytes, kInputUsage);
    std::memset(instances.mapped, 0, 4 * kInstanceBytes);
    device.OneShot([&](VkCommandBuffer cb) {
      a.Build(cb, Shape{});
      b.Build(cb, Shape{});
    });
  }
  ~Scene() { device.Destroy(instances); }
  void HostWrite(const std::vector<VkAccelerationStructureInstanceKHR>& records) {
    std::memcpy(instances.mapped, records.data(), records.size() * kInstanceBytes);
  }
  void WriteReference(VkCommandBuffer cb, uint32_t i, VkDeviceAddress reference) {
    vkCmdUpdateBuffer(cb, instances.buffer, i * kInstanceBytes + kReferenceOffset, sizeof reference, &reference);
  }
  void Record(VkCommandBuffer cb, uint32_t count, VkBuildAccelerationStructureModeKHR mode) {
    asval_test::InputsWritten(cb);
    tlas.Record(cb, instances, count, mode);
  }
  vkkit::Device& device;
  Inputs inputs;
  Blas a, b;
  Tlas tlas;
  vkkit::Buffer instances;
};

CORPUS_CASE(TlasUpdateHostActivates, "capture-tlas-update-host-write-activates-instance", "history",
            "a TLAS built with instance 1 hidden (reference 0); the per-frame update command buffer, recorded once, "
            "is submitted after the host wrote BLAS b's address into instance 1",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03663"}) {
  Scene scene(device);
  Commands commands(device);
  scene.HostWrite({Instance(scene.a.address(), 0), Instance(0, 1)});
  device.OneShot([&](VkCommandBuffer cb) { scene.Record(cb, 2, kBuild); });
  VkCommandBuffer update = commands.Begin();
  scene.Record(update, 2, kUpdate);
  commands.End(update);
  scene.HostWrite({Instance(scene.a.address(), 0, 0.5f), Instance(0, 1, 0.5f)});
  commands.Submit(update);
  scene.HostWrite({Instance(scene.a.address(), 0, 1.0f), Instance(scene.b.address(), 1, 1.0f)});
  commands.Submit(update);
}

CORPUS_CASE(TlasUpdateDeviceDeactivates, "capture-tlas-update-device-write-hides-instance", "history",
            "a TLAS over two BLASes; a vkCmdUpdateBuffer in front of the TLAS update sets instance 1's reference to 0",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03664"}) {
  Scene scene(device);
  scene.HostWrite({Instance(scene.a.address(), 0), Instance(scene.b.address(), 1)});
  device.OneShot([&](VkCommandBuffer cb) { scene.Record(cb, 2, kBuild); });
  device.OneShot([&](VkCommandBuffer cb) {
    scene.WriteReference(cb, 1, 0);
    scene.Record(cb, 2, kUpdate);
  });
}

CORPUS_CASE(TlasRebuildChangesActivity, "capture-tlas-rebuild-hides-instance-then-updates", "history",
            "a TLAS over two BLASes; instance 1 hidden (reference 0 by vkCmdUpdateBuffer) and the TLAS rebuilt, not "
            "updated; the following updates keep it hidden while moving instance 0",
            {}) {
  Scene scene(device);
  scene.HostWrite({Instance(scene.a.address(), 0), Instance(scene.b.address(), 1)});
  device.OneShot([&](VkCommandBuffer cb) { scene.Record(cb, 2, kBuild); });
  device.OneShot([&](VkCommandBuffer cb) {
    scene.WriteReference(cb, 1, 0);
    scene.Record(cb, 2, kBuild);
  });
  for (int frame = 1; frame <= 2; ++frame) {
    scene.HostWrite({Instance(scene.a.address(), 0, 0.5f * frame), Instance(0, 1, 0.5f * frame)});
    device.OneShot([&](VkCommandBuffer cb) { scene.Record(cb, 2, kUpdate); });
  }
}

CORPUS_CASE(TlasReferencesDestroyedBlas, "capture-tlas-rebuild-references-destroyed-blas", "history",
            "a TLAS rebuilt every frame by one command buffer; after frame 1 BLAS b is destroyed (its pool buffer "
            "stays) but its instance is left in the mapped instance buffer",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-06707"}) {
  Scene scene(device);
  Commands commands(device);
  scene.HostWrite({Instance(scene.a.address(), 0), Instance(scene.b.address(), 1)});
  VkCommandBuffer rebuild = commands.Begin();
  scene.Record(rebuild, 2, kBuild);
  commands.End(rebuild);
  commands.Submit(rebuild);
  scene.b.DestroyHandle();
  commands.Submit(rebuild);
}

CORPUS_CASE(TlasStagingCopyDestroyedBlas, "capture-tlas-instances-copied-after-blas-destroyed", "history",
            "the TLAS instances staged on the host while BLAS b lived, b destroyed, then the staging copied into the "
            "instance buffer by vkCmdCopyBuffer in front of the TLAS build",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-06707"}) {
  Scene scene(device);
  Staging staging(device, 2 * kInstanceBytes);
  staging.Fill(std::vector<VkAccelerationStructureInstanceKHR>{Instance(scene.a.address(), 0),
                                                               Instance(scene.b.address(), 1)});
  scene.b.DestroyHandle();
  device.OneShot([&](VkCommandBuffer cb) {
    staging.CopyTo(cb, scene.instances.buffer, 0, 2 * kInstanceBytes);
    scene.Record(cb, 2, kBuild);
  });
}

CORPUS_CASE(TlasBlasRecreatedSameAddress, "capture-tlas-blas-recreated-at-same-address", "history",
            "BLAS b destroyed and created again in the same pool buffer and offset (the same device address), rebuilt; "
            "the TLAS command buffer recorded before is resubmitted with the unchanged instances",
            {}) {
  Scene scene(device);
  Commands commands(device);
  scene.HostWrite({Instance(scene.a.address(), 0), Instance(scene.b.address(), 1)});
  VkCommandBuffer rebuild = commands.Begin();
  scene.Record(rebuild, 2, kBuild);
  commands.End(rebuild);
  commands.Submit(rebuild);
  scene.b.Recreate();
  device.OneShot([&](VkCommandBuffer cb) { scene.b.Build(cb, Shape{}); });
  scene.HostWrite({Instance(scene.a.address(), 0), Instance(scene.b.address(), 1)});
  commands.Submit(rebuild);
}

CORPUS_CASE(TlasStaleBeyondCount, "capture-tlas-stale-record-beyond-instance-count", "history",
            "an instance buffer holding, past the instance count the TLAS build reads, a record of a destroyed BLAS",
            {}) {
  Scene scene(device);
  scene.HostWrite({Instance(scene.a.address(), 0), Instance(scene.b.address(), 1)});
  scene.b.DestroyHandle();
  const VkDeviceAddress live = scene.a.address();
  device.OneShot([&](VkCommandBuffer cb) {
    vkCmdUpdateBuffer(cb, scene.instances.buffer, kReferenceOffset, sizeof live, &live);
    scene.Record(cb, 1, kBuild);
  });
}

CORPUS_CASE(TlasRemovesDestroyedBlas, "capture-tlas-hides-instance-before-blas-destroyed", "history",
            "BLAS b destroyed after the TLAS build that referenced it completed; the next frames hide its instance "
            "(reference 0 by vkCmdUpdateBuffer) and rebuild the TLAS",
            {}) {
  Scene scene(device);
  scene.HostWrite({Instance(scene.a.address(), 0), Instance(scene.b.address(), 1)});
  device.OneShot([&](VkCommandBuffer cb) { scene.Record(cb, 2, kBuild); });
  scene.b.DestroyHandle();
  for (int frame = 1; frame <= 2; ++frame) {
    device.OneShot([&](VkCommandBuffer cb) {
      scene.WriteReference(cb, 1, 0);
      scene.Record(cb, 2, kBuild);
    });
  }
}

CORPUS_CASE(TlasSecondaryDestroyedBlas, "capture-tlas-build-in-secondary-references-destroyed-blas", "history",
            "a secondary command buffer recorded while BLAS b lived writes the instances (vkCmdUpdateBuffer) and builds "
            "the TLAS; b is destroyed before the primary executing it is submitted",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-06707"}) {
  Scene scene(device);
  Commands commands(device);
  const std::vector<VkAccelerationStructureInstanceKHR> records = {Instance(scene.a.address(), 0),
                                                                   Instance(scene.b.address(), 1)};
  VkCommandBuffer secondary = commands.BeginSecondary();
  vkCmdUpdateBuffer(secondary, scene.instances.buffer, 0, 2 * kInstanceBytes, records.data());
  scene.Record(secondary, 2, kBuild);
  commands.End(secondary);
  VkCommandBuffer primary = commands.Begin();
  vkCmdExecuteCommands(primary, 1, &secondary);
  commands.End(primary);
  scene.b.DestroyHandle();
  commands.Submit(primary);
}

CORPUS_CASE(TlasUpdateDestroyedBlas, "capture-tlas-update-references-destroyed-blas", "history",
            "a TLAS over BLASes a and b updated every frame by one command buffer; b is destroyed (its pool buffer "
            "stays) and the next update still reads its instance",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-06707"}) {
  Scene scene(device);
  Commands commands(device);
  scene.HostWrite({Instance(scene.a.address(), 0), Instance(scene.b.address(), 1)});
  device.OneShot([&](VkCommandBuffer cb) { scene.Record(cb, 2, kBuild); });
  VkCommandBuffer update = commands.Begin();
  scene.Record(update, 2, kUpdate);
  commands.End(update);
  commands.Submit(update);
  scene.b.DestroyHandle();
  commands.Submit(update);
}

CORPUS_CASE(TlasUpdateMovesInstances, "capture-tlas-update-changes-transforms-masks", "history",
            "a TLAS with a hidden instance updated every frame from host-written records: transforms, masks and "
            "custom indices change, each instance's reference stays (0 stays 0)",
            {}) {
  Scene scene(device);
  Commands commands(device);
  scene.HostWrite({Instance(scene.a.address(), 0), Instance(0, 1), Instance(scene.b.address(), 2)});
  device.OneShot([&](VkCommandBuffer cb) { scene.Record(cb, 3, kBuild); });
  VkCommandBuffer update = commands.Begin();
  scene.Record(update, 3, kUpdate);
  commands.End(update);
  for (uint32_t frame = 1; frame <= 3; ++frame) {
    VkAccelerationStructureInstanceKHR first = Instance(scene.a.address(), 0, 0.5f * frame);
    first.mask = static_cast<uint32_t>(0xff >> frame);
    first.instanceCustomIndex = frame;
    VkAccelerationStructureInstanceKHR hidden = Instance(0, 1, 1.0f * frame);
    hidden.mask = 0x80;
    VkAccelerationStructureInstanceKHR third = Instance(scene.b.address(), 2, -0.5f * frame);
    third.transform.matrix[1][1] = 1.0f + 0.25f * frame;
    scene.HostWrite({first, hidden, third});
    commands.Submit(update);
  }
}

CORPUS_CASE(TlasLateBlas, "capture-tlas-references-blas-created-after-recording", "history",
            "the TLAS command buffer recorded first; a BLAS created and built later is written into the mapped "
            "instances before the TLAS command buffer is submitted",
            {}) {
  Scene scene(device);
  Commands commands(device);
  VkCommandBuffer rebuild = commands.Begin();
  scene.Record(rebuild, 2, kBuild);
  commands.End(rebuild);
  Blas late(device, scene.inputs);
  device.OneShot([&](VkCommandBuffer cb) { late.Build(cb, Shape{}); });
  scene.HostWrite({Instance(scene.a.address(), 0), Instance(late.address(), 1)});
  commands.Submit(rebuild);
  scene.HostWrite({Instance(scene.a.address(), 0), Instance(scene.b.address(), 1)});
  commands.Submit(rebuild);
}

}  // namespace
