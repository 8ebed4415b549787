// The caller's floating-point mode must not leak into the builder: apps (and so the layer's calling
// thread) may run with flush-to-zero, denormals-are-zero or another rounding mode, under which subnormal
// coordinates would flush to 0 (a vertex outside its own box) and distinct subnormal vertices would
// compare equal (a triangle wrongly degenerate). Every entry point sets the IEEE default for its call and
// restores the caller's mode.
#include <catch2/catch_test_macros.hpp>

#include <xmmintrin.h>

#include <cstring>
#include <vector>

#include "asval/builder/bvh.h"
#include "asval/builder/classify.h"
#include "bvh_checks.h"

using namespace asval::builder;

namespace {

constexpr unsigned kAppMode = 0x1F80u | 0x8000u /*FTZ*/ | 0x0040u /*DAZ*/ | 0x6000u /*round toward zero*/;

float Subnormal(uint32_t bits) {
    float f;
    std::memcpy(&f, &bits, 4);
    return f;
}

class AppMode {
public:
    AppMode() : saved_(_mm_getcsr()) { _mm_setcsr(kAppMode); }
    ~AppMode() { _mm_setcsr(saved_); }
    static void Restore(unsigned mode) { _mm_setcsr(mode); }
    unsigned Saved() const { return saved_; }

private:
    unsigned saved_;
};

}  // namespace

TEST_CASE("a caller's FTZ / DAZ / rounding mode neither changes results nor leaks", "[bvh][float-mode]") {
    // 2000 triangles with subnormal, pairwise distinct coordinates: none degenerate in IEEE arithmetic.
    const uint32_t n = 2000;
    std::vector<float> v;
    for (uint32_t t = 0; t < n; ++t) {
        const uint32_t b = 16 + 64 * t;  // subnormal bit patterns (exponent field 0)
        const float p[9] = {Subnormal(b), Subnormal(b + 1), Subnormal(b + 2), Subnormal(b + 20), Subnormal(b + 3),
                            Subnormal(b + 4), Subnormal(b + 5), Subnormal(b + 40), Subnormal(b + 6)};
        v.insert(v.end(), p, p + 9);
    }
    TriangleGeometryView view;
    view.vertexData = v.data();
    view.vertexDataBytes = v.size() * 4;
    view.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    view.vertexStride = 12;
    view.maxVertex = 3 * n - 1;
    view.range.primitiveCount = n;

    ClassifyResult classified;
    BuildInput input;
    Bvh bvh;
    {
        const AppMode app;
        classified = ClassifyTriangles(view, nullptr, nullptr);
        CHECK(_mm_getcsr() == kAppMode);
        AppendTriangles(view, false, 0, &input);
        CHECK(_mm_getcsr() == kAppMode);
        BuildOptions o;
        o.threads = 2;
        BuildInput copy = input;
        bvh = BuildBvh(std::move(copy), o);
        CHECK(_mm_getcsr() == kAppMode);
    }
    // Checked in the default mode.
    CHECK(classified.degenerate == 0);
    REQUIRE(input.refs.size() == n);  // degenerate ones would have been dropped (allowUpdate false)
    for (uint32_t t = 0; t < n; ++t) {
        const PrimRef& r = input.refs[t];
        for (int k = 0; k < 3; ++k)
            for (int c = 0; c < 3; ++c) {
                const float x = v[9 * t + 3 * k + c];
                REQUIRE(r.lo[c] <= x);
                REQUIRE(x <= r.hi[c]);
            }
    }
    const auto report = bvhcheck::CheckTree(bvh, bvhcheck::RefsById(input), 8, true);
    INFO(report.first);
    CHECK(report.violations == 0);
}
