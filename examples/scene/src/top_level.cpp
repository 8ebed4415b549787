#include "top_level.h"

#include <algorithm>
#include <cmath>

namespace scene {

namespace {

uint32_t Hash(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

float Unit(uint32_t x) { return static_cast<float>(Hash(x) & 0xFFFFu) / 65535.0f; }

}  // namespace

TopLevel::TopLevel(Gpu& gpu, uint32_t count, const Prototype& ground, const std::vector<Prototype>& prototypes)
    : gpu_(gpu) {
  prototypes_.push_back(ground);
  prototypes_.insert(prototypes_.end(), prototypes.begin(), prototypes.end());
  uint32_t total_weight = 0;
  for (const Prototype& p : prototypes) total_weight += p.weight;

  placements_.push_back(Placement{0, 0, 0, 1, 0, 0, 0, false, false});
  const uint32_t objects = count > 0 ? count - 1 : 0;
  const uint32_t side = static_cast<uint32_t>(std::ceil(std::sqrt(static_cast<double>(std::max(objects, 1u)))));
  const float spacing = 2.4f;
  for (uint32_t i = 0; i < objects; ++i) {
    Placement p{};
    uint32_t pick = Hash(i * 3 + 1) % total_weight;
    p.prototype = 1;
    while (pick >= prototypes_[p.prototype].weight) pick -= prototypes_[p.prototype++].weight;
    p.x = (static_cast<float>(i % side) - 0.5f * static_cast<float>(side - 1)) * spacing + 0.6f * (Unit(i * 7 + 2) - 0.5f);
    p.z = (static_cast<float>(i / side) - 0.5f * static_cast<float>(side - 1)) * spacing + 0.6f * (Unit(i * 7 + 3) - 0.5f);
    p.scale = prototypes_[p.prototype].scale * (0.8f + 0.4f * Unit(i * 7 + 4));
    p.angle = 6.2831853f * Unit(i * 7 + 5);
    p.spin = 1.5f * (Unit(i * 7 + 6) - 0.5f);
    p.material = 1 + Hash(i * 7 + 8) % 7;
    p.inactive = i % 29 == 7;
    p.masked = i % 101 == 50;
    if (p.inactive) ++inactive_;
    placements_.push_back(p);
  }

  const VkDeviceSize bytes = placements_.size() * sizeof(VkAccelerationStructureInstanceKHR);
  instance_block_ = gpu_.CreateBlock(2 * AlignUp(bytes, 65536), Memory::kHostVisible);
  for (Buffer& b : instances_) {
    b = gpu_.CreateBufferIn(instance_block_, bytes, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
  }
  gpu_.Name(VK_OBJECT_TYPE_BUFFER, instances_[0].buffer, "instances (even frames)");
  gpu_.Name(VK_OBJECT_TYPE_BUFFER, instances_[1].buffer, "instances (odd frames)");
  const VkAccelerationStructureBuildSizesInfoKHR sizes = Input(0).QuerySizes(gpu_);
  tlas_ = gpu_.CreateAccelerationStructure(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR,
                                           sizes.accelerationStructureSize, "scene TLAS");
  scratch_ = gpu_.CreateBuffer(std::max(sizes.buildScratchSize, sizes.updateScratchSize),
                               VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, Memory::kDeviceLocal);
  gpu_.Name(VK_OBJECT_TYPE_BUFFER, scratch_.buffer, "TLAS scratch");
}

TopLevel::~TopLevel() {
  gpu_.Destroy(tlas_);
  gpu_.Destroy(scratch_);
  for (Buffer& b : instances_) gpu_.Destroy(b);
  gpu_.Destroy(instance_block_);
}

void TopLevel::WriteInstances(uint32_t parity, float time) {
  VkAccelerationStructureInstanceKHR* out = instances(parity);
  for (size_t i = 0; i < placements_.size(); ++i) {
    const Placement& p = placements_[i];
    const Prototype& proto = prototypes_[p.prototype];
    const float a = p.angle + p.spin * time;
    const float c = std::cos(a) * p.scale, s = std::sin(a) * p.scale;
    VkAccelerationStructureInstanceKHR inst{};
    const float rows[3][4] = {{c, 0, s, p.x}, {0, p.scale, 0, 0}, {-s, 0, c, p.z}};
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 4; ++k) inst.transform.matrix[r][k] = rows[r][k];
    inst.instanceCustomIndex = p.material;
    inst.mask = p.masked ? 0x00 : 0xFF;
    inst.instanceShaderBindingTableRecordOffset = proto.hit_group;
    inst.flags = VK_GEOMETRY_INSTANCE_TRIANGLE_FACING_CULL_DISABLE_BIT_KHR;
    inst.accelerationStructureReference = p.inactive ? 0 : proto.address;
    out[i] = inst;
  }
}

BuildInput TopLevel::Input(uint32_t parity) const {
  BuildInput in;
  in.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
  in.flags = kFlags;
  VkAccelerationStructureGeometryKHR g{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  g.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
  g.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
  g.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
  g.geometry.instances.arrayOfPointers = VK_FALSE;
  g.geometry.instances.data.deviceAddress = instances_[parity].address;
  in.geometries = {g};
  VkAccelerationStructureBuildRangeInfoKHR range{};
  range.primitiveCount = count();
  in.ranges = {range};
  return in;
}

void TopLevel::RecordBuild(VkCommandBuffer cb, uint32_t parity, VkBuildAccelerationStructureModeKHR mode) const {
  const bool update = mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
  const BuildInput in = Input(parity);
  scene::RecordBuild(gpu_, cb, {in.Info(mode, update ? tlas_.handle : VK_NULL_HANDLE, tlas_.handle, scratch_.address)}, {&in});
  Barrier(cb, kBuildStage, kBuildWrites, VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR,
          VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR);
}

}  // namespace scene
