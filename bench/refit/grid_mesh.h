#pragma once
// The mesh every structure of the refit benchmark is made of: a grid of quads in the unit square, two triangles
// per quad, cut to exactly the number of triangles asked for. Positions are vec4 (the compute shader's
// std430 array); the shader displaces z every frame.
#include <cstdint>
#include <vector>

namespace refit {

struct GridMesh {
  std::vector<float> rest;        // x, y, z, 1 per vertex
  std::vector<uint32_t> indices;  // 3 per triangle
  uint32_t vertex_count() const { return static_cast<uint32_t>(rest.size() / 4); }
  uint32_t triangle_count() const { return static_cast<uint32_t>(indices.size() / 3); }
};

GridMesh MakeGridMesh(uint32_t triangles);

}  // namespace refit
