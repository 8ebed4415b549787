// Bounds containment (G7): every active primitive's exactly transformed vertices, and every instance's
// exact image of its BLAS box, lie inside every ancestor box. Exactness comes from exact.cpp (no rounding).
// 10^5 trials per CI run; ASVAL_TEST_SCALE=100 gives the documented 10^7 run.
#include <catch2/catch_test_macros.hpp>

#include <array>
#include <cmath>
#include <cstring>

#include "asval/builder/bvh.h"
#include "bvh_checks.h"
#include "exact.h"
#include "test_support.h"

using namespace asval::builder;
using testsupport::Rng;

namespace {

// Random 3x4 transform: rotation-ish, shear, per-axis scale 1e-3..1e3, translation up to `maxT`, random sign.
void RandomTransform(Rng& r, double maxT, float m[12]) {
    for (int row = 0; row < 3; ++row) {
        const double scale = std::pow(10.0, -3 + 6 * r.Unit());
        for (int c = 0; c < 3; ++c) m[4 * row + c] = float((r.Unit() * 2 - 1) * scale);
        m[4 * row + 3] = float((r.Unit() * 2 - 1) * std::pow(10.0, std::log10(maxT) * r.Unit()));
    }
    if (r.Below(8) == 0) m[4 * r.Below(3) + r.Below(3)] = 0.0f;  // singular-ish rows happen
}

bool Inside(const float row[4], const float xyz[3], float lo, float hi) {
    return exact::SignAffineMinus(row, xyz, lo) >= 0 && exact::SignAffineMinus(row, xyz, hi) <= 0;
}

}  // namespace

TEST_CASE("triangles under VkTransformMatrixKHR: exact vertices inside every ancestor box", "[bounds][property]") {
    const uint64_t trials = 100000 * testsupport::TestScale();
    const uint32_t perBuild = 500;
    Rng rng(2024);
    uint64_t violations = 0, checked = 0;
    std::string first;
    for (uint64_t done = 0; done < trials; done += perBuild) {
        const double coordScale = std::pow(10.0, -3 + 10 * rng.Unit());  // 1e-3 .. 1e7
        std::vector<float> v(size_t(perBuild) * 9);
        for (float& x : v) x = float((rng.Unit() * 2 - 1) * coordScale);
        float m[12];
        RandomTransform(rng, 1e7, m);
        TriangleGeometryView view;
        view.vertexData = v.data();
        view.vertexDataBytes = v.size() * 4;
        view.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
        view.vertexStride = 12;
        view.maxVertex = perBuild * 3 - 1;
        view.transformData = m;
        view.transformDataBytes = sizeof m;
        view.range.primitiveCount = perBuild;
        BuildInput in;
        AppendTriangles(view, true, 0, &in);
        const auto refs = bvhcheck::RefsById(in);
        BuildOptions o;
        o.mode = (done / perBuild) % 2 ? BuildMode::Lbvh : BuildMode::BinnedSah;
        const Bvh bvh = BuildBvh(std::move(in), o);
        const auto tree = bvhcheck::CheckTree(bvh, refs, 8, true);  // parents contain children
        violations += tree.violations;
        if (tree.violations && first.empty()) first = tree.first;
        bvhcheck::ForEachLeafRef(bvh, [&](const BvhNode& leaf, uint32_t id) {
            for (int k = 0; k < 3; ++k) {
                const float* p = &v[size_t(id) * 9 + size_t(k) * 3];
                for (int a = 0; a < 3; ++a) {
                    ++checked;
                    if (!Inside(m + 4 * a, p, leaf.lo[a], leaf.hi[a])) {
                        if (violations++ == 0) first = "triangle " + std::to_string(id);
                    }
                }
            }
        });
    }
    INFO(first);
    CHECK(violations == 0);
    CHECK(checked == trials * 9);
}

TEST_CASE("instances: the exact image of the BLAS box lies inside the stored box and every ancestor", "[bounds][property]") {
    const uint64_t trials = 100000 * testsupport::TestScale();
    const uint32_t perBuild = 500;
    Rng rng(77);
    uint64_t violations = 0;
    std::string first;
    double inflationSum = 0, exactInflationSum = 0;
    uint64_t inflationCount = 0;
    struct Ctx { const std::vector<std::array<float, 6>>* boxes; };
    for (uint64_t done = 0; done < trials; done += perBuild) {
        std::vector<VkAccelerationStructureInstanceKHR> inst(perBuild);
        std::vector<std::array<float, 6>> blasBoxes(perBuild);
        for (uint32_t i = 0; i < perBuild; ++i) {
            float m[12];
            RandomTransform(rng, 1e7, m);
            std::memcpy(&inst[i].transform, m, sizeof m);
            inst[i].accelerationStructureReference = i + 1;
            const double size = std::pow(10.0, -3 + 6 * rng.Unit());
            for (int a = 0; a < 3; ++a) {
                const double c = (rng.Unit() * 2 - 1) * size * 10;
                const double h = size * rng.Unit();
                blasBoxes[i][size_t(a)] = float(c - h);
                blasBoxes[i][size_t(a) + 3] = float(c + h);
            }
        }
        InstanceGeometryView view;
        view.data = inst.data();
        view.dataBytes = inst.size() * sizeof inst[0];
        view.range.primitiveCount = perBuild;
        Ctx ctx{&blasBoxes};
        BuildInput in;
        AppendInstances(view, [](uint64_t ref, void* user) {
            const auto& b = (*static_cast<Ctx*>(user)->boxes)[ref - 1];
            BlasSummary s;
            s.known = true;
            s.activePrimitives = 1;
            for (int a = 0; a < 3; ++a) { s.lo[a] = b[size_t(a)]; s.hi[a] = b[size_t(a) + 3]; }
            return s;
        }, &ctx, 0, &in);
        const auto refs = bvhcheck::RefsById(in);
        BuildOptions o;
        o.mode = (done / perBuild) % 2 ? BuildMode::Lbvh : BuildMode::BinnedSah;
        const Bvh bvh = BuildBvh(std::move(in), o);
        const auto tree = bvhcheck::CheckTree(bvh, refs, 8, true);
        violations += tree.violations;
        if (tree.violations && first.empty()) first = tree.first;
        for (uint32_t i = 0; i < perBuild; ++i) {
            // The image of a box is the hull of its 8 corner images: checking the corners is exact.
            const float* m = &inst[i].transform.matrix[0][0];
            const PrimRef& stored = refs[i];
            for (int corner = 0; corner < 8; ++corner) {
                const float p[3] = {blasBoxes[i][size_t((corner & 1) ? 3 : 0)], blasBoxes[i][size_t((corner & 2) ? 4 : 1)],
                                    blasBoxes[i][size_t((corner & 4) ? 5 : 2)]};
                for (int a = 0; a < 3; ++a)
                    if (!Inside(m + 4 * a, p, stored.lo[a], stored.hi[a])) {
                        if (violations++ == 0) first = "instance " + std::to_string(i);
                    }
            }
            // G7's inflation metric: surface area of the stored box over that of the tightest float box
            // holding the exact image (the cost of our rounding method, not of the float grid), for
            // instances within |coords| <= 1e3. The inflation over the exact image is reported too.
            double exactLo[3], exactHi[3];
            bool near = true;
            for (int a = 0; a < 3; ++a) {
                long double lo = m[4 * a + 3], hi = m[4 * a + 3];
                for (int c = 0; c < 3; ++c) {
                    const long double x = (long double)m[4 * a + c] * blasBoxes[i][size_t(c)];
                    const long double y = (long double)m[4 * a + c] * blasBoxes[i][size_t(c) + 3];
                    lo += std::min(x, y);
                    hi += std::max(x, y);
                }
                exactLo[a] = double(lo);
                exactHi[a] = double(hi);
                near &= std::fabs(exactLo[a]) <= 1e3 && std::fabs(exactHi[a]) <= 1e3;
            }
            auto area = [](const double* l, const double* h) {
                const double e0 = h[0] - l[0], e1 = h[1] - l[1], e2 = h[2] - l[2];
                return e0 * e1 + e1 * e2 + e2 * e0;
            };
            const double storedLo[3] = {stored.lo[0], stored.lo[1], stored.lo[2]};
            const double storedHi[3] = {stored.hi[0], stored.hi[1], stored.hi[2]};
            // The tightest float box that holds the image: the exact bounds rounded outward once.
            double bestLo[3], bestHi[3];
            for (int a = 0; a < 3; ++a) {
                float l = float(exactLo[a]), h = float(exactHi[a]);
                if (double(l) > exactLo[a]) l = std::nextafter(l, -INFINITY);
                if (double(h) < exactHi[a]) h = std::nextafter(h, INFINITY);
                bestLo[a] = l;
                bestHi[a] = h;
            }
            const double exactArea = area(exactLo, exactHi);
            if (near && exactArea > 1e-6) {
                inflationSum += area(storedLo, storedHi) / area(bestLo, bestHi) - 1;
                exactInflationSum += area(storedLo, storedHi) / exactArea - 1;
                ++inflationCount;
            }
        }
    }
    INFO(first);
    CHECK(violations == 0);
    const double meanInflation = inflationSum / double(inflationCount);
    WARN("instance boxes within 1e3 (" << inflationCount << "): mean area inflation " << meanInflation
         << " over the tightest float box, " << exactInflationSum / double(inflationCount) << " over the exact image");
    CHECK(inflationCount > trials / 20);
    CHECK(meanInflation <= 1e-3);
}

TEST_CASE("norm formats: the box holds the exact rational value c / K of every code", "[bounds][norm]") {
    struct Case { VkFormat format; uint32_t bits; bool isSigned; };
    const Case cases[] = {{VK_FORMAT_R16G16_SNORM, 16, true}, {VK_FORMAT_R8G8_SNORM, 8, true},
                          {VK_FORMAT_R16G16_UNORM, 16, false}, {VK_FORMAT_R8G8_UNORM, 8, false},
                          {VK_FORMAT_A2B10G10R10_UNORM_PACK32, 10, false}};
    for (const Case& c : cases) {
        const uint32_t codes = 1u << c.bits;
        const uint32_t bytes = c.format == VK_FORMAT_A2B10G10R10_UNORM_PACK32 ? 4 : 2 * (c.bits / 8);
        std::vector<uint8_t> v(size_t(codes) * 3 * bytes, 0);
        for (uint32_t code = 0; code < codes; ++code)
            for (uint32_t k = 0; k < 3; ++k) {
                uint8_t* p = v.data() + (size_t(code) * 3 + k) * bytes;
                testsupport::WriteComponent(c.format, p, 0, code);     // X = the code under test
                testsupport::WriteComponent(c.format, p, 1, k * 5);    // Y differs per vertex
            }
        TriangleGeometryView view;
        view.vertexData = v.data();
        view.vertexDataBytes = v.size();
        view.vertexFormat = c.format;
        view.vertexStride = bytes;
        view.maxVertex = codes * 3 - 1;
        view.range.primitiveCount = codes;
        BuildInput in;
        AppendTriangles(view, true, 0, &in);  // degenerate (X shared, Z shared): kept with ALLOW_UPDATE
        REQUIRE(in.refs.size() == codes);
        const double k = c.isSigned ? double((1u << (c.bits - 1)) - 1) : double((1u << c.bits) - 1);
        uint64_t bad = 0, tight = 0;
        for (const PrimRef& r : in.refs) {
            double code = double(r.id);
            if (c.isSigned && code >= double(codes / 2)) code -= double(codes);
            if (code < -k) code = -k;  // max(c / K, -1)
            // lo * K <= code <= hi * K, evaluated exactly (float times a <= 16-bit integer fits in double).
            bad += !(double(r.lo[0]) * k <= code && code <= double(r.hi[0]) * k);
            tight += r.lo[0] == r.hi[0] || std::nextafter(r.lo[0], INFINITY) == r.hi[0];
        }
        INFO("format " << int(c.format));
        CHECK(bad == 0);
        CHECK(tight == codes);  // never wider than the two floats around the exact value
    }
}
