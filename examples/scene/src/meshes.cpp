#include "meshes.h"

#include <cmath>
#include <map>
#include <utility>

#include "half.h"

namespace scene {

namespace {

Vec3 Normalize(Vec3 v) {
  const float l = std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
  return {v.x / l, v.y / l, v.z / l};
}

// A unit icosphere: 12 vertices, 20 faces, each face split in four `levels` times.
void Icosphere(int levels, std::vector<Vec3>* vertices, std::vector<uint32_t>* indices) {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  *vertices = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
               {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (Vec3& v : *vertices) v = Normalize(v);
  *indices = {0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4, 11, 10, 2, 10, 7, 6, 7, 1, 8,
              3, 9, 4, 3, 4, 2, 3, 2, 6, 3, 6, 8, 3, 8, 9, 4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9, 8, 1};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoints;
    auto midpoint = [&](uint32_t a, uint32_t b) {
      const auto key = a < b ? std::make_pair(a, b) : std::make_pair(b, a);
      auto it = midpoints.find(key);
      if (it != midpoints.end()) return it->second;
      const Vec3& p = (*vertices)[a];
      const Vec3& q = (*vertices)[b];
      vertices->push_back(Normalize({(p.x + q.x) / 2, (p.y + q.y) / 2, (p.z + q.z) / 2}));
      const uint32_t index = static_cast<uint32_t>(vertices->size() - 1);
      midpoints.emplace(key, index);
      return index;
    };
    std::vector<uint32_t> next;
    for (size_t i = 0; i < indices->size(); i += 3) {
      const uint32_t a = (*indices)[i], b = (*indices)[i + 1], c = (*indices)[i + 2];
      const uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      next.insert(next.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
    }
    *indices = std::move(next);
  }
}

// Deterministic bumps for the rock (no random generator: the image must be the same on every run).
float Bumps(const Vec3& d) { return 0.08f * std::sin(7.0f * d.x + 2.0f) * std::sin(5.0f * d.y) * std::cos(6.0f * d.z); }

VkTransformMatrixKHR Transform(float scale, float angle_y, Vec3 t) {
  const float c = std::cos(angle_y) * scale, s = std::sin(angle_y) * scale;
  VkTransformMatrixKHR m{};
  const float rows[3][4] = {{c, 0, s, t.x}, {0, scale, 0, t.y}, {-s, 0, c, t.z}};
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 4; ++k) m.matrix[r][k] = rows[r][k];
  return m;
}

void AddGrid(DeformingMeshes* m, uint32_t columns, uint32_t rows, float width, float height, float bottom) {
  DeformingGeometry& g = m->cloth;
  g.first_vertex = static_cast<uint32_t>(m->rest.size());
  for (uint32_t r = 0; r < rows; ++r) {
    for (uint32_t c = 0; c < columns; ++c) {
      RestVertex v{};
      v.position[0] = width * static_cast<float>(c) / static_cast<float>(columns - 1);
      v.position[1] = bottom + height * static_cast<float>(r) / static_cast<float>(rows - 1);
      v.mode = kWave;
      v.phase = 0.3f * static_cast<float>(r);
      m->rest.push_back(v);
    }
  }
  // Holes: these vertices are NaN in every frame, so every triangle around them is inactive.
  const uint32_t holes[][2] = {{5, 3}, {10, 6}, {12, 2}};
  for (const auto& h : holes) m->rest[g.first_vertex + h[1] * columns + h[0]].mode = kInactive;
  for (uint32_t r = 0; r + 1 < rows; ++r) {
    for (uint32_t c = 0; c + 1 < columns; ++c) {
      const uint32_t a = r * columns + c, b = a + 1, d = a + columns, e = d + 1;
      for (uint32_t tri : {a, b, e, a, e, d}) g.indices.push_back(tri);
    }
  }
  for (size_t i = 0; i < g.indices.size(); i += 3) {
    bool inactive = false;
    for (size_t k = 0; k < 3; ++k) inactive = inactive || m->rest[g.first_vertex + g.indices[i + k]].mode == kInactive;
    if (inactive) ++m->inactive_triangles;
  }
}

// Confetti around the flag: triangles of their own vertices that start as a point (degenerate) and grow
// across refits, which an update may do.
void AddConfetti(DeformingMeshes* m, uint32_t count) {
  DeformingGeometry& g = m->cloth;
  for (uint32_t k = 0; k < count; ++k) {
    const Vec3 center{0.25f + 0.3f * static_cast<float>(k), 2.45f + 0.1f * static_cast<float>(k % 2), 0.25f};
    const Vec3 corners[3] = {{-0.08f, -0.06f, 0}, {0.08f, -0.06f, 0}, {0, 0.09f, 0}};
    const uint32_t base = static_cast<uint32_t>(m->rest.size()) - g.first_vertex;
    for (const Vec3& c : corners) {
      RestVertex v{{center.x + c.x, center.y + c.y, center.z + c.z}, kGrow, {center.x, center.y, center.z}, 0};
      m->rest.push_back(v);
      g.indices.push_back(base + static_cast<uint32_t>(&c - corners));
    }
    ++m->degenerate_triangles;
  }
  g.vertex_count = static_cast<uint32_t>(m->rest.size()) - g.first_vertex;
}

void AddPole(DeformingMeshes* m) {
  DeformingGeometry& g = m->pole;
  g.first_vertex = static_cast<uint32_t>(m->rest.size());
  for (uint32_t i = 0; i < 8; ++i) {
    RestVertex v{};
    v.position[0] = (i & 1) ? 0.05f : -0.05f;
    v.position[1] = (i & 2) ? 2.5f : 0.0f;
    v.position[2] = (i & 4) ? 0.05f : -0.05f;
    v.mode = kStatic;
    m->rest.push_back(v);
  }
  g.vertex_count = 8;
  g.indices = {0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1,
               2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4, 1, 5, 7, 1, 7, 3};
}

void AddBlob(DeformingMeshes* m) {
  std::vector<Vec3> unit;
  DeformingGeometry& g = m->blob;
  Icosphere(1, &unit, &g.indices);
  g.first_vertex = static_cast<uint32_t>(m->rest.size());
  g.vertex_count = static_cast<uint32_t>(unit.size());
  const Vec3 center{0, 0.7f, 0};
  for (const Vec3& d : unit) {
    RestVertex v{{center.x + 0.6f * d.x, center.y + 0.6f * d.y, center.z + 0.6f * d.z}, kPulse,
                 {center.x, center.y, center.z}, 3.0f * d.y};
    m->rest.push_back(v);
  }
}

}  // namespace

RockMesh MakeRock() {
  std::vector<Vec3> unit;
  RockMesh rock;
  Icosphere(2, &unit, &rock.indices);
  for (const Vec3& d : unit) {
    const float r = 0.6f + Bumps(d);
    InterleavedVertex v{{r * d.x, 0.55f + r * d.y * 0.8f, r * d.z},
                        {d.x, d.y, d.z},
                        {0.5f + std::atan2(d.z, d.x) / 6.2831853f, 0.5f - std::asin(d.y) / 3.1415927f}};
    rock.vertices.push_back(v);
  }
  return rock;
}

TorusMesh MakeTorus() {
  TorusMesh torus;
  const uint32_t ring = 16, tube = 8;
  for (uint32_t i = 0; i < ring; ++i) {
    const float u = 6.2831853f * static_cast<float>(i) / ring;
    for (uint32_t j = 0; j < tube; ++j) {
      const float v = 6.2831853f * static_cast<float>(j) / tube;
      const float r = 0.55f + 0.2f * std::cos(v);
      // Standing up: the ring lies in the XY plane, resting on the ground.
      const float p[4] = {r * std::cos(u), 0.78f + r * std::sin(u), 0.2f * std::sin(v), 1.0f};
      for (float c : p) torus.vertices.push_back(FloatToHalf(c));
    }
  }
  for (uint32_t i = 0; i < ring; ++i) {
    for (uint32_t j = 0; j < tube; ++j) {
      const uint16_t a = static_cast<uint16_t>(i * tube + j);
      const uint16_t b = static_cast<uint16_t>(((i + 1) % ring) * tube + j);
      const uint16_t c = static_cast<uint16_t>(((i + 1) % ring) * tube + (j + 1) % tube);
      const uint16_t d = static_cast<uint16_t>(i * tube + (j + 1) % tube);
      for (uint16_t k : {a, b, c, a, c, d}) torus.indices.push_back(k);
    }
  }
  return torus;
}

CrateMesh MakeCrates() {
  CrateMesh crates;
  // 6 faces x 2 triangles of a unit cube centred on the origin.
  const int faces[6][4][3] = {{{-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}},     {{1, -1, -1}, {-1, -1, -1}, {-1, 1, -1}, {1, 1, -1}},
                              {{-1, -1, -1}, {-1, -1, 1}, {-1, 1, 1}, {-1, 1, -1}}, {{1, -1, 1}, {1, -1, -1}, {1, 1, -1}, {1, 1, 1}},
                              {{-1, 1, 1}, {1, 1, 1}, {1, 1, -1}, {-1, 1, -1}},     {{-1, -1, -1}, {1, -1, -1}, {1, -1, 1}, {-1, -1, 1}}};
  for (const auto& f : faces) {
    for (int k : {0, 1, 2, 0, 2, 3}) crates.vertices.push_back({0.5f * f[k][0], 0.5f * f[k][1], 0.5f * f[k][2]});
  }
  crates.transforms = {Transform(1.0f, 0.0f, {0, 0, 0}), Transform(0.9f, 0.0f, {0, 0.45f, 0}),
                       Transform(0.5f, 0.5f, {0.15f, 1.15f, 0.1f})};
  return crates;
}

std::vector<AabbRecord> MakeSphereBoxes() {
  std::vector<AabbRecord> boxes;
  for (uint32_t id = 0; id < 18; ++id) {
    const float cx = static_cast<float>(id % 3) - 1.0f;
    const float cy = 0.5f + static_cast<float>((id / 3) % 3);
    const float cz = static_cast<float>(id / 9) - 0.5f;
    const float r = 0.45f;
    boxes.push_back({{cx - r, cy - r, cz - r, cx + r, cy + r, cz + r}, r, id});
  }
  return boxes;
}

GroundMesh MakeGround(float e) {
  return {{{-e, 0, -e}, {e, 0, -e}, {e, 0, e}, {-e, 0, e}}, {0, 2, 1, 0, 3, 2}};
}

DeformingMeshes MakeDeformingMeshes() {
  DeformingMeshes m;
  AddGrid(&m, 16, 10, 2.0f, 1.2f, 1.25f);
  AddConfetti(&m, 6);
  AddPole(&m);
  AddBlob(&m);
  return m;
}

}  // namespace scene
