#pragma once
// The scene's geometry, generated on the host: what each bottom-level structure is built from. Sizes are
// small on purpose (the scene must run fast on lavapipe); variety is the point: formats, strides, index
// types, transforms, several geometries per structure, AABBs, inactive and degenerate triangles.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

namespace scene {

struct Vec3 {
  float x, y, z;
};

// An interleaved vertex as engines store them: the build reads the position with a 32-byte stride.
struct InterleavedVertex {
  float position[3];
  float normal[3];
  float uv[2];
};
static_assert(sizeof(InterleavedVertex) == 32);

// The application's AABB record: VkAabbPositionsKHR plus a payload, so the stride is 32, not 24.
struct AabbRecord {
  VkAabbPositionsKHR box;
  float radius;
  uint32_t material;
};
static_assert(sizeof(AabbRecord) == 32);

// What the compute shader animates (see shaders/deform.comp for the modes).
struct RestVertex {
  float position[3];
  float mode;
  float center[3];
  float phase;
};
static_assert(sizeof(RestVertex) == 32);

enum DeformMode : uint32_t { kStatic = 0, kWave = 1, kPulse = 2, kInactive = 3, kGrow = 4 };

struct RockMesh {  // uint32 indices, R32G32B32_SFLOAT inside a 32-byte interleaved vertex
  std::vector<InterleavedVertex> vertices;
  std::vector<uint32_t> indices;
};

struct TorusMesh {  // uint16 indices, R16G16B16A16_SFLOAT vertices
  std::vector<uint16_t> vertices;  // 4 halves per vertex
  std::vector<uint16_t> indices;
};

struct CrateMesh {  // non-indexed triangles; two geometries, each placed by its own VkTransformMatrixKHR
  std::vector<Vec3> vertices;  // 36: one cube
  std::vector<VkTransformMatrixKHR> transforms;  // [0] unused, [1] and [2]: at offsets 48 and 96
};

struct GroundMesh {  // uint32 indices, tightly packed R32G32B32_SFLOAT
  std::vector<Vec3> vertices;
  std::vector<uint32_t> indices;
};

// A geometry of a deforming structure: a slice of the animated vertex array plus its own indices.
struct DeformingGeometry {
  uint32_t first_vertex = 0;
  uint32_t vertex_count = 0;
  std::vector<uint32_t> indices;  // relative to first_vertex
};

// All animated vertices in one array (one compute dispatch), and the geometries that use them:
// the flag (cloth with holes of inactive triangles and growing degenerate triangles, plus its pole: two
// geometries in one structure) and the blob (one geometry).
struct DeformingMeshes {
  std::vector<RestVertex> rest;
  DeformingGeometry cloth;
  DeformingGeometry pole;
  DeformingGeometry blob;
  uint32_t inactive_triangles = 0;   // in the cloth
  uint32_t degenerate_triangles = 0;  // in the cloth at time 0
};

RockMesh MakeRock();
TorusMesh MakeTorus();
CrateMesh MakeCrates();
std::vector<AabbRecord> MakeSphereBoxes();  // must match shaders/sphere.rint's grid
GroundMesh MakeGround(float half_extent);
DeformingMeshes MakeDeformingMeshes();

}  // namespace scene
