#include "static_blases.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "meshes.h"

namespace scene {

namespace {

// Appends bytes at an aligned offset of a staging vector; returns the offset.
template <typename T>
VkDeviceSize Append(std::vector<char>* bytes, const std::vector<T>& items, VkDeviceSize alignment = 64) {
  const VkDeviceSize offset = AlignUp(bytes->size(), alignment);
  bytes->resize(offset + items.size() * sizeof(T));
  std::memcpy(bytes->data() + offset, items.data(), items.size() * sizeof(T));
  return offset;
}

VkAccelerationStructureBuildRangeInfoKHR Range(uint32_t primitives, uint32_t transform_offset = 0) {
  VkAccelerationStructureBuildRangeInfoKHR r{};
  r.primitiveCount = primitives;
  r.transformOffset = transform_offset;
  return r;
}

}  // namespace

const char* StaticBlases::Name(Kind kind) {
  switch (kind) {
    case kGround: return "ground";
    case kRock: return "rock";
    case kTorus: return "torus";
    case kCrates: return "crates";
    case kSpheres: return "spheres";
    case kCount: break;
  }
  return "?";
}

StaticBlases::StaticBlases(Gpu& gpu) : gpu_(gpu) {
  Upload();
  BuildAndCompact();
}

StaticBlases::~StaticBlases() {
  for (AccelerationStructure& as : compacted_) gpu_.Destroy(as);
  gpu_.Destroy(geometry_);
}

void StaticBlases::Upload() {
  const GroundMesh ground = MakeGround(120.0f);
  const RockMesh rock = MakeRock();
  const TorusMesh torus = MakeTorus();
  const CrateMesh crates = MakeCrates();
  const std::vector<AabbRecord> spheres = MakeSphereBoxes();

  std::vector<char> bytes;
  const VkDeviceSize ground_v = Append(&bytes, ground.vertices), ground_i = Append(&bytes, ground.indices);
  const VkDeviceSize rock_v = Append(&bytes, rock.vertices), rock_i = Append(&bytes, rock.indices);
  const VkDeviceSize torus_v = Append(&bytes, torus.vertices), torus_i = Append(&bytes, torus.indices);
  const VkDeviceSize crate_v = Append(&bytes, crates.vertices), crate_t = Append(&bytes, crates.transforms);
  const VkDeviceSize sphere_b = Append(&bytes, spheres);
  geometry_ = gpu_.CreateBuffer(bytes.size(), VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR,
                                Memory::kHostVisible);
  std::memcpy(geometry_.mapped, bytes.data(), bytes.size());
  gpu_.Name(VK_OBJECT_TYPE_BUFFER, geometry_.buffer, "static geometry");
  const VkDeviceAddress base = geometry_.address;

  for (BuildInput& in : inputs_) {
    in.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    in.flags = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR |
               VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
  }
  const auto count = [](size_t n) { return static_cast<uint32_t>(n); };
  inputs_[kGround].geometries = {TriangleGeometry(VK_FORMAT_R32G32B32_SFLOAT, base + ground_v, sizeof(Vec3),
                                                  count(ground.vertices.size() - 1), VK_INDEX_TYPE_UINT32,
                                                  base + ground_i, 0)};
  inputs_[kGround].ranges = {Range(count(ground.indices.size() / 3))};
  inputs_[kRock].geometries = {TriangleGeometry(VK_FORMAT_R32G32B32_SFLOAT, base + rock_v, sizeof(InterleavedVertex),
                                                count(rock.vertices.size() - 1), VK_INDEX_TYPE_UINT32,
                                                base + rock_i, 0)};
  inputs_[kRock].ranges = {Range(count(rock.indices.size() / 3))};
  inputs_[kTorus].geometries = {TriangleGeometry(VK_FORMAT_R16G16B16A16_SFLOAT, base + torus_v, 4 * sizeof(uint16_t),
                                                 count(torus.vertices.size() / 4 - 1), VK_INDEX_TYPE_UINT16,
                                                 base + torus_i, 0)};
  inputs_[kTorus].ranges = {Range(count(torus.indices.size() / 3))};
  // Two geometries over the same 36 vertices, each placed by its own matrix (transformOffset 48 and 96).
  const VkAccelerationStructureGeometryKHR crate = TriangleGeometry(
      VK_FORMAT_R32G32B32_SFLOAT, base + crate_v, sizeof(Vec3), count(crates.vertices.size() - 1),
      VK_INDEX_TYPE_NONE_KHR, 0, base + crate_t);
  inputs_[kCrates].geometries = {crate, crate};
  inputs_[kCrates].ranges = {Range(count(crates.vertices.size() / 3), sizeof(VkTransformMatrixKHR)),
                             Range(count(crates.vertices.size() / 3), 2 * sizeof(VkTransformMatrixKHR))};

  VkAccelerationStructureGeometryKHR boxes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  boxes.geometryType = VK_GEOMETRY_TYPE_AABBS_KHR;
  boxes.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
  boxes.geometry.aabbs.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_AABBS_DATA_KHR;
  boxes.geometry.aabbs.data.deviceAddress = base + sphere_b;
  boxes.geometry.aabbs.stride = sizeof(AabbRecord);
  inputs_[kSpheres].geometries = {boxes};
  inputs_[kSpheres].ranges = {Range(count(spheres.size()))};
}

void StaticBlases::BuildAndCompact() {
  const VkDeviceSize slice_alignment =
      std::max<VkDeviceSize>(128, gpu_.as_properties().minAccelerationStructureScratchOffsetAlignment);
  std::array<AccelerationStructure, kCount> built;
  std::array<VkDeviceSize, kCount> scratch_offsets{};
  VkDeviceSize scratch_size = 0;
  for (int k = 0; k < kCount; ++k) {
    const VkAccelerationStructureBuildSizesInfoKHR sizes = inputs_[k].QuerySizes(gpu_);
    built[k] = gpu_.CreateAccelerationStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
                                                sizes.accelerationStructureSize,
                                                (std::string(Name(static_cast<Kind>(k))) + " (before compaction)").c_str());
    built_bytes_ += sizes.accelerationStructureSize;
    scratch_offsets[k] = scratch_size;
    scratch_size += AlignUp(sizes.buildScratchSize, slice_alignment);
  }
  Buffer scratch = gpu_.CreateBuffer(scratch_size, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, Memory::kDeviceLocal);
  gpu_.Name(VK_OBJECT_TYPE_BUFFER, scratch.buffer, "static build scratch");

  VkQueryPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  pool_info.queryType = VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR;
  pool_info.queryCount = kCount;
  VkQueryPool pool = VK_NULL_HANDLE;
  Check(vkCreateQueryPool(gpu_.device(), &pool_info, nullptr, &pool), "vkCreateQueryPool");

  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos;
  std::vector<const BuildInput*> inputs;
  std::vector<VkAccelerationStructureKHR> handles;
  for (int k = 0; k < kCount; ++k) {
    infos.push_back(inputs_[k].Info(VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR, VK_NULL_HANDLE, built[k].handle,
                                    scratch.address + scratch_offsets[k]));
    inputs.push_back(&inputs_[k]);
    handles.push_back(built[k].handle);
  }
  VkCommandBuffer cb = gpu_.AllocateCommandBuffer();
  gpu_.Begin(cb, VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT);
  vkCmdResetQueryPool(cb, pool, 0, kCount);
  RecordBuild(gpu_, cb, infos, inputs);
  Barrier(cb, kBuildStage, kBuildWrites, kBuildStage, kBuildReads);
  gpu_.vk().CmdWriteAccelerationStructuresPropertiesKHR(cb, kCount, handles.data(),
                                                        VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, pool, 0);
  gpu_.End(cb);
  Check(gpu_.SubmitAndWait({cb}), "static builds: vkQueueSubmit");

  std::array<VkDeviceSize, kCount> compact_sizes{};
  Check(vkGetQueryPoolResults(gpu_.device(), pool, 0, kCount, sizeof(compact_sizes), compact_sizes.data(),
                              sizeof(VkDeviceSize), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
        "vkGetQueryPoolResults");

  Check(vkResetCommandBuffer(cb, 0), "vkResetCommandBuffer");
  gpu_.Begin(cb, VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT);
  for (int k = 0; k < kCount; ++k) {
    compacted_[k] = gpu_.CreateAccelerationStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, compact_sizes[k],
                                                     Name(static_cast<Kind>(k)));
    compacted_bytes_ += compact_sizes[k];
    VkCopyAccelerationStructureInfoKHR copy{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_INFO_KHR};
    copy.src = built[k].handle;
    copy.dst = compacted_[k].handle;
    copy.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR;
    gpu_.vk().CmdCopyAccelerationStructureKHR(cb, &copy);
  }
  gpu_.End(cb);
  Check(gpu_.SubmitAndWait({cb}), "compaction: vkQueueSubmit");
  gpu_.FreeCommandBuffer(cb);

  for (AccelerationStructure& as : built) gpu_.Destroy(as);
  gpu_.Destroy(scratch);
  vkDestroyQueryPool(gpu_.device(), pool, nullptr);
}

}  // namespace scene
