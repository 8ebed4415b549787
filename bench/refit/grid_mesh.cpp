#include "grid_mesh.h"

#include <cmath>

namespace refit {

GridMesh MakeGridMesh(uint32_t triangles) {
  const uint32_t quads = (triangles + 1) / 2;
  const uint32_t columns = static_cast<uint32_t>(std::ceil(std::sqrt(static_cast<double>(quads))));
  const uint32_t rows = (quads + columns - 1) / columns;
  GridMesh mesh;
  for (uint32_t r = 0; r <= rows; ++r) {
    for (uint32_t c = 0; c <= columns; ++c) {
      mesh.rest.insert(mesh.rest.end(), {static_cast<float>(c) / static_cast<float>(columns),
                                         static_cast<float>(r) / static_cast<float>(rows), 0.0f, 1.0f});
    }
  }
  const uint32_t stride = columns + 1;
  for (uint32_t q = 0; q < quads; ++q) {
    const uint32_t r = q / columns, c = q % columns;
    const uint32_t v = r * stride + c;
    mesh.indices.insert(mesh.indices.end(), {v, v + 1, v + stride + 1});
    if (mesh.indices.size() / 3 < triangles) mesh.indices.insert(mesh.indices.end(), {v, v + stride + 1, v + stride});
  }
  return mesh;
}

}  // namespace refit
