// VK_NV_ray_tracing_motion_blur bounds: every exact position at every sampled time t in [0, 1] lies inside
// the stored box (and, through CheckTree, every ancestor). Exact arithmetic: exact_dyadic.h. Times are
// dyadic (k / 2^16), so the interpolation weights are exact too. CI: a few 10^4 trials per kind;
// ASVAL_TEST_SCALE multiplies them (documented long run).
#include <catch2/catch_test_macros.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "asval/builder/bvh.h"
#include "asval/builder/bvh_triangles.h"
#include "bvh_checks.h"
#include "exact_dyadic.h"
#include "test_support.h"

using namespace asval::builder;
using exact::Dyadic;
using testsupport::Rng;

namespace {

constexpr int64_t kW = 1 << 16;  // t = k / kW

Dyadic D(float f) { return Dyadic::FromFloat(f); }
Dyadic I(int64_t v) { return Dyadic::FromInt(v); }

// 0, 1 and random interior times (as k of k / kW).
std::vector<int64_t> Times(Rng& r, int interior) {
    std::vector<int64_t> ks = {0, kW, kW / 2};  // 1/2: where q1 = -q0 interpolates through 0
    for (int i = 0; i < interior; ++i) ks.push_back(1 + int64_t(r.Below(uint32_t(kW - 1))));
    return ks;
}

float Signed(Rng& r, double magnitude) { return float((r.Unit() * 2 - 1) * magnitude); }
double LogUniform(Rng& r, double lo10, double hi10) { return std::pow(10.0, lo10 + (hi10 - lo10) * r.Unit()); }

void RandomMatrix(Rng& r, double maxT, float m[12]) {
    for (int row = 0; row < 3; ++row) {
        const double scale = LogUniform(r, -3, 3);
        for (int c = 0; c < 3; ++c) m[4 * row + c] = Signed(r, scale);
        m[4 * row + 3] = Signed(r, LogUniform(r, 0, std::log10(maxT)));
    }
    if (r.Below(8) == 0) m[4 * r.Below(3) + r.Below(3)] = 0.0f;
}

void RandomBox(Rng& r, float lo[3], float hi[3]) {
    const double size = LogUniform(r, -3, 3);
    for (int a = 0; a < 3; ++a) {
        const double c = (r.Unit() * 2 - 1) * size * 10, h = size * r.Unit();
        lo[a] = float(c - h);
        hi[a] = float(c + h);
    }
}

// sx a b pvx sy c pvy sz pvz qx qy qz qw tx ty tz
void RandomSrt(Rng& r, float d[16], const float* other) {
    const double s = LogUniform(r, -3, 3);
    for (int i : {0, 4, 7}) d[i] = Signed(r, s);
    for (int i : {1, 2, 5}) d[i] = r.Below(2) ? Signed(r, s) : 0.0f;
    for (int i : {3, 6, 8}) d[i] = Signed(r, LogUniform(r, -3, 3));
    double q[4], n = 0;
    for (double& x : q) { x = r.Unit() * 2 - 1; n += x * x; }
    n = std::sqrt(n);
    const uint32_t kind = r.Below(8);
    // Mostly unit (to float rounding); sometimes scaled (non-unit, |q| up to 2); sometimes the other end's
    // negation (the same rotation: the interpolated quaternion passes through 0 at t = 1/2).
    const double scale = kind == 0 ? 0.25 + 1.75 * r.Unit() : 1.0;
    for (int i = 0; i < 4; ++i) d[9 + i] = float(q[i] / n * scale);
    if (kind == 1 && other) for (int i = 0; i < 4; ++i) d[9 + i] = -other[9 + i];
    if (kind == 2 && other) for (int i = 0; i < 4; ++i) d[9 + i] = other[9 + i];
    const double tMax = LogUniform(r, 0, 7);
    for (int i = 13; i < 16; ++i) d[i] = Signed(r, tMax);
}

struct BlasTable {
    std::vector<std::array<float, 6>> boxes;
    std::vector<uint32_t> active;
};

BlasSummary Lookup(uint64_t ref, void* user) {
    const auto* t = static_cast<const BlasTable*>(user);
    BlasSummary s;
    s.known = ref >= 1 && ref <= t->boxes.size();
    if (!s.known) return s;
    const auto& b = t->boxes[ref - 1];
    s.activePrimitives = t->active[ref - 1];
    for (int a = 0; a < 3; ++a) { s.lo[a] = b[size_t(a)]; s.hi[a] = b[size_t(a) + 3]; }
    return s;
}

// Record i of a plain motion array (stride 160) of the given type.
uint8_t* Record(std::vector<uint8_t>& buf, uint32_t i) { return buf.data() + 160ull * i; }

// Builds, checks the tree (parents hold children, every kept id inside its leaf) and returns refs by id.
std::vector<PrimRef> BuildAndCheck(BuildInput in, bool lbvh, uint64_t* violations, std::string* first) {
    auto refs = bvhcheck::RefsById(in);
    BuildOptions o;
    o.mode = lbvh ? BuildMode::Lbvh : BuildMode::BinnedSah;
    const Bvh bvh = BuildBvh(std::move(in), o);
    const auto tree = bvhcheck::CheckTree(bvh, refs, 8, true);
    *violations += tree.violations;
    if (tree.violations && first->empty()) *first = tree.first;
    return refs;
}

// W^s * lo <= value <= W^s * hi (value already scaled by W^s), exactly.
bool Within(const Dyadic& value, const Dyadic& scale, float lo, float hi) {
    return exact::Compare(value, scale * D(lo)) >= 0 && exact::Compare(value, scale * D(hi)) <= 0;
}

}  // namespace

TEST_CASE("matrix motion instances: exact image at every sampled t inside the stored box", "[bounds][property][motion]") {
    const uint64_t trials = 10000 * testsupport::TestScale();
    const uint32_t perBuild = 250;
    Rng rng(5150);
    uint64_t violations = 0, checks = 0;
    std::string first;
    Dyadic::ResetOverflow();
    for (uint64_t done = 0; done < trials; done += perBuild) {
        std::vector<uint8_t> buf(160ull * perBuild, 0);
        BlasTable blas;
        for (uint32_t i = 0; i < perBuild; ++i) {
            VkAccelerationStructureMatrixMotionInstanceNV m = {};
            RandomMatrix(rng, 1e7, &m.transformT0.matrix[0][0]);
            if (rng.Below(4) == 0) m.transformT1 = m.transformT0;  // no motion
            else RandomMatrix(rng, 1e7, &m.transformT1.matrix[0][0]);
            m.accelerationStructureReference = i + 1;
            const uint32_t type = VK_ACCELERATION_STRUCTURE_MOTION_INSTANCE_TYPE_MATRIX_MOTION_NV;
            std::memcpy(Record(buf, i), &type, 4);
            std::memcpy(Record(buf, i) + 8, &m, sizeof m);
            std::array<float, 6> b;
            RandomBox(rng, b.data(), b.data() + 3);
            blas.boxes.push_back(b);
            blas.active.push_back(rng.Below(16) == 0 ? 0u : 1u);  // some degenerate: the origin moves
        }
        InstanceGeometryView view;
        view.data = buf.data();
        view.dataBytes = buf.size();
        view.motionInstances = true;
        view.range.primitiveCount = perBuild;
        BuildInput in;
        AppendInstances(view, Lookup, &blas, 0, &in);
        REQUIRE(in.refs.size() == perBuild);
        const auto refs = BuildAndCheck(std::move(in), (done / perBuild) % 2, &violations, &first);
        for (uint32_t i = 0; i < perBuild; ++i) {
            VkAccelerationStructureMatrixMotionInstanceNV m;
            std::memcpy(&m, Record(buf, i) + 8, sizeof m);
            const float* m0 = &m.transformT0.matrix[0][0];
            const float* m1 = &m.transformT1.matrix[0][0];
            const auto& b = blas.boxes[i];
            const bool degenerate = blas.active[i] == 0;
            for (int64_t k : Times(rng, 6)) {
                for (int corner = 0; corner < (degenerate ? 1 : 8); ++corner) {
                    Dyadic x[3];
                    for (int c = 0; c < 3; ++c)
                        x[c] = degenerate ? Dyadic{} : D(b[size_t((corner >> c) & 1 ? c + 3 : c)]);
                    for (int a = 0; a < 3; ++a) {
                        // W p(t) = (W - k) (M0 x) + k (M1 x): the entry-wise interpolation, times W.
                        Dyadic r0 = D(m0[4 * a + 3]), r1 = D(m1[4 * a + 3]);
                        for (int c = 0; c < 3; ++c) { r0 = r0 + D(m0[4 * a + c]) * x[c]; r1 = r1 + D(m1[4 * a + c]) * x[c]; }
                        const Dyadic v = I(kW - k) * r0 + I(k) * r1;
                        ++checks;
                        if (!Within(v, I(kW), refs[i].lo[a], refs[i].hi[a]) && violations++ == 0)
                            first = "matrix instance " + std::to_string(i) + " t=" + std::to_string(k);
                    }
                }
            }
        }
    }
    INFO(first);
    CHECK(!Dyadic::Overflowed());
    CHECK(violations == 0);
    CHECK(checks > trials * 8 * 3);
}

TEST_CASE("SRT motion instances: exact image at every sampled t inside the stored box, both quaternion readings",
          "[bounds][property][motion]") {
    const uint64_t trials = 3000 * testsupport::TestScale();
    const uint32_t perBuild = 200;
    Rng rng(1893);
    uint64_t violations = 0, checks = 0, skippedZeroQ = 0;
    double sweptRatioSum = 0;  // stored box volume^(1/3) over that of the sampled exact points' box
    uint64_t sweptCount = 0;
    std::string first;
    Dyadic::ResetOverflow();
    for (uint64_t done = 0; done < trials; done += perBuild) {
        std::vector<uint8_t> buf(160ull * perBuild, 0);
        BlasTable blas;
        for (uint32_t i = 0; i < perBuild; ++i) {
            VkAccelerationStructureSRTMotionInstanceNV s = {};
            float d0[16], d1[16];
            RandomSrt(rng, d0, nullptr);
            RandomSrt(rng, d1, d0);
            std::memcpy(&s.transformT0, d0, 64);
            std::memcpy(&s.transformT1, d1, 64);
            s.accelerationStructureReference = i + 1;
            const uint32_t type = VK_ACCELERATION_STRUCTURE_MOTION_INSTANCE_TYPE_SRT_MOTION_NV;
            std::memcpy(Record(buf, i), &type, 4);
            std::memcpy(Record(buf, i) + 8, &s, sizeof s);
            std::array<float, 6> b;
            RandomBox(rng, b.data(), b.data() + 3);
            blas.boxes.push_back(b);
            blas.active.push_back(rng.Below(16) == 0 ? 0u : 1u);
        }
        InstanceGeometryView view;
        view.data = buf.data();
        view.dataBytes = buf.size();
        view.motionInstances = true;
        view.range.primitiveCount = perBuild;
        BuildInput in;
        AppendInstances(view, Lookup, &blas, 0, &in);
        REQUIRE(in.refs.size() == perBuild);
        const auto refs = BuildAndCheck(std::move(in), (done / perBuild) % 2, &violations, &first);
        for (uint32_t i = 0; i < perBuild; ++i) {
            float d[2][16];
            std::memcpy(d[0], Record(buf, i) + 8, 64);
            std::memcpy(d[1], Record(buf, i) + 8 + 64, 64);
            const auto& b = blas.boxes[i];
            const bool degenerate = blas.active[i] == 0;
            long double seenLo[3] = {INFINITY, INFINITY, INFINITY}, seenHi[3] = {-INFINITY, -INFINITY, -INFINITY};
            for (int64_t k : Times(rng, 6)) {
                // Every SRT value at time t, times W: L(j) = (W - k) d0[j] + k d1[j].
                Dyadic L[16];
                for (int j = 0; j < 16; ++j) L[j] = I(kW - k) * D(d[0][j]) + I(k) * D(d[1][j]);
                const Dyadic &qx = L[9], &qy = L[10], &qz = L[11], &qw = L[12];
                const Dyadic xx = qx * qx, yy = qy * qy, zz = qz * qz, ww = qw * qw;
                const Dyadic xy = qx * qy, xz = qx * qz, yz = qy * qz, wx = qw * qx, wy = qw * qy, wz = qw * qz;
                const Dyadic two = I(2), w2 = I(kW) * I(kW);
                const Dyadic off[3][3] = {{Dyadic{}, two * (xy - wz), two * (xz + wy)},
                                          {two * (xy + wz), Dyadic{}, two * (yz - wx)},
                                          {two * (xz - wy), two * (yz + wx), Dyadic{}}};
                // (a) rotation by q / |q|: R = Rh(q) / |q|^2, Rh homogeneous; (b) the unit formula on q as is.
                const Dyadic diagH[3] = {ww + xx - yy - zz, ww - xx + yy - zz, ww - xx - yy + zz};
                const Dyadic diagU[3] = {w2 - two * (yy + zz), w2 - two * (xx + zz), w2 - two * (xx + yy)};
                const Dyadic n2 = xx + yy + zz + ww;
                if (n2.Sign() == 0) ++skippedZeroQ;
                for (int corner = 0; corner < (degenerate ? 1 : 8); ++corner) {
                    Dyadic x[3];
                    for (int c = 0; c < 3; ++c)
                        x[c] = degenerate ? Dyadic{} : D(b[size_t((corner >> c) & 1 ? c + 3 : c)]);
                    // W S(t) x, S = [sx a b pvx; 0 sy c pvy; 0 0 sz pvz].
                    const Dyadic y[3] = {L[0] * x[0] + L[1] * x[1] + L[2] * x[2] + L[3], L[4] * x[1] + L[5] * x[2] + L[6],
                                         L[7] * x[2] + L[8]};
                    for (int a = 0; a < 3; ++a) {
                        const Dyadic& tw = L[13 + a];  // W T(t)
                        Dyadic rh = Dyadic{}, ru = Dyadic{};
                        for (int j = 0; j < 3; ++j) {
                            rh = rh + (j == a ? diagH[a] : off[a][j]) * y[j];
                            ru = ru + (j == a ? diagU[a] : off[a][j]) * y[j];
                        }
                        // (a): W^3 |q|^2 p = N Tw + Rh(Q) Y with N = W^2 |q|^2, compared with N W lo / hi.
                        if (n2.Sign() != 0) {
                            ++checks;
                            if (!Within(n2 * tw + rh, n2 * I(kW), refs[i].lo[a], refs[i].hi[a]) && violations++ == 0)
                                first = "SRT (normalised) instance " + std::to_string(i) + " t=" + std::to_string(k);
                        }
                        // (b): W^3 p = W^2 Tw + Ru_W(Q) Y.
                        ++checks;
                        if (!Within(w2 * tw + ru, w2 * I(kW), refs[i].lo[a], refs[i].hi[a]) && violations++ == 0)
                            first = "SRT (unit formula) instance " + std::to_string(i) + " t=" + std::to_string(k);
                        // Looseness figure (long double, not a check): the normalised reading's point.
                        const long double tt = (long double)k / kW;
                        long double q[4], yy3[3];
                        for (int j = 0; j < 4; ++j) q[j] = (1 - tt) * d[0][9 + j] + tt * d[1][9 + j];
                        long double sv[9];
                        for (int j = 0; j < 9; ++j) sv[j] = (1 - tt) * d[0][j] + tt * d[1][j];
                        const long double xs[3] = {degenerate ? 0 : b[size_t((corner & 1) ? 3 : 0)],
                                                   degenerate ? 0 : b[size_t((corner & 2) ? 4 : 1)],
                                                   degenerate ? 0 : b[size_t((corner & 4) ? 5 : 2)]};
                        yy3[0] = sv[0] * xs[0] + sv[1] * xs[1] + sv[2] * xs[2] + sv[3];
                        yy3[1] = sv[4] * xs[1] + sv[5] * xs[2] + sv[6];
                        yy3[2] = sv[7] * xs[2] + sv[8];
                        const long double nn = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
                        if (nn > 0) {
                            const long double X = q[0], Y = q[1], Z = q[2], Wq = q[3];
                            const long double R[3][3] = {{Wq * Wq + X * X - Y * Y - Z * Z, 2 * (X * Y - Wq * Z), 2 * (X * Z + Wq * Y)},
                                                         {2 * (X * Y + Wq * Z), Wq * Wq - X * X + Y * Y - Z * Z, 2 * (Y * Z - Wq * X)},
                                                         {2 * (X * Z - Wq * Y), 2 * (Y * Z + Wq * X), Wq * Wq - X * X - Y * Y + Z * Z}};
                            const long double p = (1 - tt) * d[0][13 + a] + tt * d[1][13 + a] +
                                                  (R[a][0] * yy3[0] + R[a][1] * yy3[1] + R[a][2] * yy3[2]) / nn;
                            seenLo[a] = std::min(seenLo[a], p);
                            seenHi[a] = std::max(seenHi[a], p);
                        }
                    }
                }
            }
            if (!degenerate) {
                long double vs = 1, vb = 1;
                for (int a = 0; a < 3; ++a) {
                    vs *= (long double)refs[i].hi[a] - refs[i].lo[a];
                    vb *= seenHi[a] - seenLo[a];
                }
                if (vb > 0 && std::isfinite(double(vs))) { sweptRatioSum += double(std::cbrt(vs / vb)); ++sweptCount; }
            }
        }
    }
    INFO(first);
    CHECK(!Dyadic::Overflowed());
    CHECK(violations == 0);
    CHECK(checks > trials * 8 * 3);
    CHECK(skippedZeroQ > 0);  // the generator reaches the quaternion-through-zero case
    WARN("SRT boxes: mean edge ratio (cube root of volume) over the box of the sampled exact points: "
         << sweptRatioSum / double(sweptCount) << " (" << sweptCount << " instances)");
}

TEST_CASE("motion triangles: exact vertices at every sampled t inside the stored box", "[bounds][property][motion]") {
    const uint64_t trials = 10000 * testsupport::TestScale();
    const uint32_t perBuild = 250;
    Rng rng(4242);
    uint64_t violations = 0, checks = 0;
    std::string first;
    Dyadic::ResetOverflow();
    for (uint64_t done = 0; done < trials; done += perBuild) {
        const double coordScale = LogUniform(rng, -3, 7);
        std::vector<float> v0(size_t(perBuild) * 9), v1(v0.size());
        for (size_t j = 0; j < v0.size(); ++j) {
            v0[j] = Signed(rng, coordScale);
            v1[j] = rng.Below(4) == 0 ? v0[j] : Signed(rng, coordScale);
        }
        float m[12];
        RandomMatrix(rng, 1e7, m);
        const bool transformed = rng.Below(4) != 0;
        TriangleGeometryView view;
        view.vertexData = v0.data();
        view.vertexDataBytes = v0.size() * 4;
        view.motionVertexData = v1.data();
        view.motionVertexDataBytes = v1.size() * 4;
        view.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
        view.vertexStride = 12;
        view.maxVertex = perBuild * 3 - 1;
        if (transformed) { view.transformData = m; view.transformDataBytes = sizeof m; }
        view.range.primitiveCount = perBuild;
        BuildInput in;
        AppendTriangles(view, true, 0, &in);
        REQUIRE(in.refs.size() == perBuild);
        const auto refs = BuildAndCheck(std::move(in), (done / perBuild) % 2, &violations, &first);
        const float identity[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
        const float* mt = transformed ? m : identity;
        for (uint32_t i = 0; i < perBuild; ++i)
            for (int64_t k : Times(rng, 3))
                for (int vert = 0; vert < 3; ++vert)
                    for (int a = 0; a < 3; ++a) {
                        const float* p0 = &v0[size_t(i) * 9 + size_t(vert) * 3];
                        const float* p1 = &v1[size_t(i) * 9 + size_t(vert) * 3];
                        // W M(v(t)) = (W - k) M v0 + k M v1 (M affine, the weights sum to W).
                        Dyadic r0 = D(mt[4 * a + 3]), r1 = D(mt[4 * a + 3]);
                        for (int c = 0; c < 3; ++c) { r0 = r0 + D(mt[4 * a + c]) * D(p0[c]); r1 = r1 + D(mt[4 * a + c]) * D(p1[c]); }
                        ++checks;
                        if (!Within(I(kW - k) * r0 + I(k) * r1, I(kW), refs[i].lo[a], refs[i].hi[a]) && violations++ == 0)
                            first = "motion triangle " + std::to_string(i) + " t=" + std::to_string(k);
                    }
    }
    INFO(first);
    CHECK(!Dyadic::Overflowed());
    CHECK(violations == 0);
    CHECK(checks == trials * 6 * 9);  // 6 times (0, 1, 1/2, 3 random) x 3 vertices x 3 axes
}

// The spatial pre-splitter clips the time-0 triangle only, so it must leave motion geometries unsplit:
// otherwise a piece box misses the triangle at t > 0.
TEST_CASE("motion triangles: spatial pre-splits keep every time's vertices covered", "[motion]") {
    Rng rng(8080);
    const uint32_t n = 4000;
    std::vector<float> v0(size_t(n) * 9), v1(v0.size());
    for (uint32_t i = 0; i < n; ++i) {
        const bool sliver = i % 100 == 0;  // a "teapot in a stadium": 1% long slivers trigger the splitter
        const float cx = Signed(rng, 1000), cy = Signed(rng, 1000), cz = Signed(rng, 1000);
        for (int k = 0; k < 3; ++k) {
            float* p = &v0[size_t(i) * 9 + size_t(k) * 3];
            p[0] = cx + (sliver && k == 1 ? 1500.0f : Signed(rng, 0.01));
            p[1] = cy + (sliver && k == 2 ? 1500.0f : Signed(rng, 0.01));
            p[2] = cz + Signed(rng, 0.01);
            float* q = &v1[size_t(i) * 9 + size_t(k) * 3];
            for (int a = 0; a < 3; ++a) q[a] = p[a] + (sliver ? 300.0f : 0.0f);  // the slivers move
        }
    }
    TriangleGeometryView view;
    view.vertexData = v0.data();
    view.vertexDataBytes = v0.size() * 4;
    view.motionVertexData = v1.data();
    view.motionVertexDataBytes = v1.size() * 4;
    view.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    view.vertexStride = 12;
    view.maxVertex = 3 * n - 1;
    view.range.primitiveCount = n;
    const Bvh bvh = BuildTriangleBvh(&view, 1, true, BuildOptions{});
    std::vector<std::vector<const BvhNode*>> leaves(n);
    bvhcheck::ForEachLeafRef(bvh, [&](const BvhNode& leaf, uint32_t id) { leaves[id].push_back(&leaf); });
    uint64_t uncovered = 0;
    for (uint32_t i = 0; i < n; ++i)
        for (const auto* data : {&v0, &v1})
            for (int k = 0; k < 3; ++k) {
                const float* p = &(*data)[size_t(i) * 9 + size_t(k) * 3];
                bool covered = false;
                for (const BvhNode* l : leaves[i])
                    covered |= p[0] >= l->lo[0] && p[0] <= l->hi[0] && p[1] >= l->lo[1] && p[1] <= l->hi[1] &&
                               p[2] >= l->lo[2] && p[2] <= l->hi[2];
                uncovered += !covered;
            }
    CHECK(uncovered == 0);
}
