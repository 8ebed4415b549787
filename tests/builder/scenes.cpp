#include "scenes.h"

#include <algorithm>
#include <cmath>

namespace scenes {
namespace {

struct Rng {  // splitmix64
    uint64_t s;
    uint64_t Next() {
        uint64_t z = (s += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    double Unit() { return double(Next() >> 11) * 0x1p-53; }
    double Gauss() {  // Box-Muller
        const double u = std::max(Unit(), 1e-300), v = Unit();
        return std::sqrt(-2 * std::log(u)) * std::cos(6.283185307179586 * v);
    }
};

void Tri(Scene& s, const double c[3], const double d[3][3]) {
    for (int v = 0; v < 3; ++v)
        for (int a = 0; a < 3; ++a) s.vertices.push_back(float(c[a] + d[v][a]));
    ++s.triangles;
}

// A random triangle of size ~`size` around `c`.
void RandomTri(Scene& s, Rng& r, const double c[3], double size) {
    double d[3][3];
    for (auto& v : d)
        for (double& x : v) x = (r.Unit() - 0.5) * size;
    Tri(s, c, d);
}

void Shuffle(Scene& s, Rng& r) {
    for (uint32_t i = s.triangles; i > 1; --i) {
        const uint32_t j = uint32_t(r.Next() % i);
        for (int k = 0; k < 9; ++k) std::swap(s.vertices[9 * (i - 1) + k], s.vertices[9 * j + k]);
    }
}

}  // namespace

Scene Uniform(uint32_t n, uint64_t seed) {
    Scene s{"uniform", {}, {}, 0};
    Rng r{seed};
    s.vertices.reserve(size_t(n) * 9);
    const double extent = 1.5 * std::pow(double(n), -1.0 / 3.0);
    for (uint32_t i = 0; i < n; ++i) {
        const double c[3] = {r.Unit(), r.Unit(), r.Unit()};
        RandomTri(s, r, c, extent);
    }
    return s;
}

Scene Sphere(uint32_t approx) {
    Scene s{"sphere", {}, {}, 0};
    const uint32_t k = std::max<uint32_t>(1, uint32_t(std::lround(std::sqrt(approx / 12.0))));
    const uint32_t side = k + 1;
    for (int face = 0; face < 6; ++face) {
        const uint32_t base = uint32_t(s.vertices.size() / 3);
        for (uint32_t j = 0; j < side; ++j)
            for (uint32_t i = 0; i < side; ++i) {
                const double u = 2.0 * i / k - 1, v = 2.0 * j / k - 1;
                double p[3];
                const int axis = face / 2;
                const double sign = (face & 1) ? 1.0 : -1.0;
                p[axis] = sign;
                p[(axis + 1) % 3] = u;
                p[(axis + 2) % 3] = v;
                const double len = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
                for (double x : p) s.vertices.push_back(float(x / len));
            }
        for (uint32_t j = 0; j < k; ++j)
            for (uint32_t i = 0; i < k; ++i) {
                const uint32_t a = base + j * side + i, b = a + 1, c = a + side, d = c + 1;
                s.indices.insert(s.indices.end(), {a, b, d, a, d, c});
                s.triangles += 2;
            }
    }
    // Cube edges share positions but not vertices: the mesh is watertight by position, no degenerates.
    return s;
}

Scene Terrain(uint32_t approx, uint64_t seed) {
    Scene s{"terrain", {}, {}, 0};
    Rng r{seed};
    const uint32_t k = std::max<uint32_t>(2, uint32_t(std::lround(std::sqrt(approx / 2.0))) + 1);
    double amp[8], fx[8], fy[8], ph[8];
    for (int w = 0; w < 8; ++w) {
        amp[w] = 0.05 / (1 + w);
        fx[w] = 1 + 20 * r.Unit();
        fy[w] = 1 + 20 * r.Unit();
        ph[w] = 6.283185307179586 * r.Unit();
    }
    for (uint32_t j = 0; j < k; ++j)
        for (uint32_t i = 0; i < k; ++i) {
            const double x = double(i) / (k - 1), y = double(j) / (k - 1);
            double h = 0;
            for (int w = 0; w < 8; ++w) h += amp[w] * std::sin(fx[w] * x + fy[w] * y + ph[w]);
            s.vertices.insert(s.vertices.end(), {float(x), float(h), float(y)});
        }
    for (uint32_t j = 0; j + 1 < k; ++j)
        for (uint32_t i = 0; i + 1 < k; ++i) {
            const uint32_t a = j * k + i, b = a + 1, c = a + k, d = c + 1;
            s.indices.insert(s.indices.end(), {a, b, d, a, d, c});
            s.triangles += 2;
        }
    return s;
}

Scene Clustered(uint32_t n, uint64_t seed) {
    Scene s{"clustered", {}, {}, 0};
    Rng r{seed};
    double centers[32][3];
    for (auto& c : centers)
        for (double& x : c) x = (r.Unit() - 0.5) * 2000;
    s.vertices.reserve(size_t(n) * 9);
    for (uint32_t i = 0; i < n; ++i) {
        const double pick = r.Unit();
        if (pick < 0.80) {  // tiny triangles in Gaussian clusters
            const double* cc = centers[r.Next() % 32];
            const double c[3] = {cc[0] + 0.5 * r.Gauss(), cc[1] + 0.5 * r.Gauss(), cc[2] + 0.5 * r.Gauss()};
            RandomTri(s, r, c, std::pow(10.0, -3 + 2 * r.Unit()));
        } else if (pick < 0.99) {  // medium triangles anywhere
            const double c[3] = {(r.Unit() - 0.5) * 2000, (r.Unit() - 0.5) * 2000, (r.Unit() - 0.5) * 2000};
            RandomTri(s, r, c, std::pow(10.0, -2 + 3 * r.Unit()));
        } else {  // long slivers, up to 2000 long
            const double c[3] = {(r.Unit() - 0.5) * 2000, (r.Unit() - 0.5) * 2000, (r.Unit() - 0.5) * 2000};
            const double len = 2000 * r.Unit();
            double dir[3] = {r.Gauss(), r.Gauss(), r.Gauss()};
            const double norm = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]) + 1e-12;
            double d[3][3];
            for (int a = 0; a < 3; ++a) {
                d[0][a] = -0.5 * len * dir[a] / norm;
                d[1][a] = 0.5 * len * dir[a] / norm;
                d[2][a] = d[0][a] + (r.Unit() - 0.5) * 0.1;
            }
            Tri(s, c, d);
        }
    }
    Shuffle(s, r);
    return s;
}

Scene ByName(const std::string& name, uint32_t n) {
    if (name == "sphere") return Sphere(n);
    if (name == "terrain") return Terrain(n, 3);
    if (name == "clustered") return Clustered(n, 4);
    return Uniform(n, 2);
}

asval::builder::TriangleGeometryView View(const Scene& s) {
    asval::builder::TriangleGeometryView v;
    v.vertexData = s.vertices.data();
    v.vertexDataBytes = s.vertices.size() * sizeof(float);
    v.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    v.vertexStride = 12;
    v.maxVertex = uint32_t(s.vertices.size() / 3 - 1);
    if (!s.indices.empty()) {
        v.indexType = VK_INDEX_TYPE_UINT32;
        v.indexData = s.indices.data();
        v.indexDataBytes = s.indices.size() * sizeof(uint32_t);
    }
    v.range.primitiveCount = s.triangles;
    return v;
}

}  // namespace scenes
