// The anchors document's four scene families (uniform, sphere, terrain, clustered), reproducible from a
// seed, plus small helpers to hand them to the builder. Shared by the tests and the benchmarks.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "asval/builder/geometry_view.h"

namespace scenes {

struct Scene {
    std::string name;
    std::vector<float> vertices;   // xyz triples
    std::vector<uint32_t> indices; // empty: non-indexed
    uint32_t triangles = 0;
};

Scene Uniform(uint32_t triangles, uint64_t seed);
Scene Sphere(uint32_t approxTriangles);     // indexed cube-sphere, 12 k^2 triangles
Scene Terrain(uint32_t approxTriangles, uint64_t seed);  // indexed height field, 2 (k-1)^2 triangles
Scene Clustered(uint32_t triangles, uint64_t seed);
Scene ByName(const std::string& name, uint32_t triangles);

// R32G32B32_SFLOAT view of the whole scene.
asval::builder::TriangleGeometryView View(const Scene& s);

}  // namespace scenes
