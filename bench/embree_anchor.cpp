#include "embree_anchor.h"

#ifdef ASVAL_HAVE_EMBREE

#include <embree3/rtcore.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

namespace anchor {
namespace {

struct Node {
    bool leaf;
    unsigned count;
    Node* child[2];
    RTCBounds bounds[2];
};

void* CreateNode(RTCThreadLocalAllocator alloc, unsigned int, void*) {
    auto* n = static_cast<Node*>(rtcThreadLocalAlloc(alloc, sizeof(Node), 16));
    *n = Node{false, 0, {nullptr, nullptr}, {}};
    return n;
}
void SetChildren(void* node, void** children, unsigned int count, void*) {
    for (unsigned i = 0; i < count && i < 2; ++i) static_cast<Node*>(node)->child[i] = static_cast<Node*>(children[i]);
}
void SetBounds(void* node, const RTCBounds** bounds, unsigned int count, void*) {
    for (unsigned i = 0; i < count && i < 2; ++i) static_cast<Node*>(node)->bounds[i] = *bounds[i];
}
void* CreateLeaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive*, size_t n, void*) {
    auto* l = static_cast<Node*>(rtcThreadLocalAlloc(alloc, sizeof(Node), 16));
    *l = Node{true, unsigned(n), {nullptr, nullptr}, {}};
    return l;
}

// Clips triangle primID against the plane `dim = pos`, as Embree's own splitter does.
void SplitTriangle(const RTCBuildPrimitive* prim, unsigned int dim, float pos, RTCBounds* lb, RTCBounds* rb, void* user) {
    const auto* s = static_cast<const scenes::Scene*>(user);
    float v[3][3];
    for (int k = 0; k < 3; ++k) {
        const uint32_t vi = s->indices.empty() ? 3 * prim->primID + uint32_t(k) : s->indices[3 * prim->primID + uint32_t(k)];
        for (int a = 0; a < 3; ++a) v[k][a] = s->vertices[3 * vi + uint32_t(a)];
    }
    float l[2][3] = {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
    float r[2][3] = {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
    auto grow = [](float b[2][3], const float* p) {
        for (int a = 0; a < 3; ++a) { b[0][a] = std::min(b[0][a], p[a]); b[1][a] = std::max(b[1][a], p[a]); }
    };
    for (int k = 0; k < 3; ++k) {
        const float* a = v[k];
        const float* b = v[(k + 1) % 3];
        if (a[dim] <= pos) grow(l, a);
        if (a[dim] >= pos) grow(r, a);
        if ((a[dim] < pos && b[dim] > pos) || (a[dim] > pos && b[dim] < pos)) {
            const float t = (pos - a[dim]) / (b[dim] - a[dim]);
            float c[3];
            for (int i = 0; i < 3; ++i) c[i] = a[i] + t * (b[i] - a[i]);
            c[dim] = pos;
            grow(l, c);
            grow(r, c);
        }
    }
    const float plo[3] = {prim->lower_x, prim->lower_y, prim->lower_z};
    const float phi[3] = {prim->upper_x, prim->upper_y, prim->upper_z};
    float out[2][2][3];
    for (int a = 0; a < 3; ++a) {
        out[0][0][a] = std::max(l[0][a], plo[a]); out[0][1][a] = std::min(l[1][a], phi[a]);
        out[1][0][a] = std::max(r[0][a], plo[a]); out[1][1][a] = std::min(r[1][a], phi[a]);
    }
    out[0][1][dim] = std::min(out[0][1][dim], pos);
    out[1][0][dim] = std::max(out[1][0][dim], pos);
    *lb = RTCBounds{out[0][0][0], out[0][0][1], out[0][0][2], 0, out[0][1][0], out[0][1][1], out[0][1][2], 0};
    *rb = RTCBounds{out[1][0][0], out[1][0][1], out[1][0][2], 0, out[1][1][0], out[1][1][1], out[1][1][2], 0};
}

double HalfArea(const RTCBounds& b) {
    const double x = std::max(0.0, double(b.upper_x) - b.lower_x), y = std::max(0.0, double(b.upper_y) - b.lower_y),
                 z = std::max(0.0, double(b.upper_z) - b.lower_z);
    return x * y + y * z + z * x;
}

RTCBounds Union(const RTCBounds& a, const RTCBounds& b) {
    return RTCBounds{std::min(a.lower_x, b.lower_x), std::min(a.lower_y, b.lower_y), std::min(a.lower_z, b.lower_z), 0,
                     std::max(a.upper_x, b.upper_x), std::max(a.upper_y, b.upper_y), std::max(a.upper_z, b.upper_z), 0};
}

// sum_inner A + sum_leaf count * A, for the subtree under a node whose box is `box`.
double Sah(const Node* n, const RTCBounds& box) {
    if (n->leaf) return n->count * HalfArea(box);
    double s = HalfArea(box);
    for (int i = 0; i < 2; ++i)
        if (n->child[i]) s += Sah(n->child[i], n->bounds[i]);
    return s;
}

std::vector<RTCBuildPrimitive> Prims(const scenes::Scene& s) {
    std::vector<RTCBuildPrimitive> p(s.triangles);
    for (uint32_t t = 0; t < s.triangles; ++t) {
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (int k = 0; k < 3; ++k) {
            const uint32_t vi = s.indices.empty() ? 3 * t + uint32_t(k) : s.indices[3 * t + uint32_t(k)];
            for (int a = 0; a < 3; ++a) {
                lo[a] = std::min(lo[a], s.vertices[3 * vi + uint32_t(a)]);
                hi[a] = std::max(hi[a], s.vertices[3 * vi + uint32_t(a)]);
            }
        }
        p[t] = RTCBuildPrimitive{lo[0], lo[1], lo[2], 0, hi[0], hi[1], hi[2], t};
    }
    return p;
}

}  // namespace

bool Available() { return true; }

Result UserBvh(const scenes::Scene& s, int quality, int threads) {
    const std::string cfg = "threads=" + std::to_string(threads);
    RTCDevice dev = rtcNewDevice(cfg.c_str());
    std::vector<RTCBuildPrimitive> base = Prims(s);
    std::vector<RTCBuildPrimitive> prims(base.size() * 2 + 16);  // room for spatial splits
    std::copy(base.begin(), base.end(), prims.begin());
    RTCBVH bvh = rtcNewBVH(dev);
    RTCBuildArguments a = rtcDefaultBuildArguments();
    a.buildQuality = RTCBuildQuality(quality);
    a.maxBranchingFactor = 2;
    a.maxDepth = 1024;
    a.minLeafSize = 1;
    a.maxLeafSize = 8;
    a.traversalCost = 1;
    a.intersectionCost = 1;
    a.bvh = bvh;
    a.primitives = prims.data();
    a.primitiveCount = base.size();
    a.primitiveArrayCapacity = prims.size();
    a.createNode = CreateNode;
    a.setNodeChildren = SetChildren;
    a.setNodeBounds = SetBounds;
    a.createLeaf = CreateLeaf;
    a.splitPrimitive = SplitTriangle;
    a.userPtr = const_cast<scenes::Scene*>(&s);
    const auto t0 = std::chrono::steady_clock::now();
    const Node* root = static_cast<const Node*>(rtcBuildBVH(&a));
    const auto t1 = std::chrono::steady_clock::now();
    Result r;
    r.seconds = std::chrono::duration<double>(t1 - t0).count();
    RTCBounds box{INFINITY, INFINITY, INFINITY, 0, -INFINITY, -INFINITY, -INFINITY, 0};
    for (const auto& p : base) box = Union(box, RTCBounds{p.lower_x, p.lower_y, p.lower_z, 0, p.upper_x, p.upper_y, p.upper_z, 0});
    if (!root->leaf) {  // the root's own box is the union of its children
        box = root->bounds[0];
        if (root->child[1]) box = Union(box, root->bounds[1]);
    }
    r.sah = Sah(root, box) / HalfArea(box);
    rtcReleaseBVH(bvh);
    rtcReleaseDevice(dev);
    return r;
}

double SceneCommit(const scenes::Scene& s, int quality, int threads) {
    const std::string cfg = "threads=" + std::to_string(threads);
    RTCDevice dev = rtcNewDevice(cfg.c_str());
    RTCScene scene = rtcNewScene(dev);
    rtcSetSceneBuildQuality(scene, RTCBuildQuality(quality));
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    std::vector<uint32_t> idx = s.indices;
    if (idx.empty())
        for (uint32_t i = 0; i < 3 * s.triangles; ++i) idx.push_back(i);
    std::vector<float> vtx = s.vertices;
    vtx.resize(vtx.size() + 4);  // Embree reads 16 bytes for the last vertex
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, vtx.data(), 0, 12, s.vertices.size() / 3);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, idx.data(), 0, 12, s.triangles);
    rtcSetGeometryBuildQuality(g, RTCBuildQuality(quality));
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
    const auto t0 = std::chrono::steady_clock::now();
    rtcCommitScene(scene);
    const auto t1 = std::chrono::steady_clock::now();
    rtcReleaseScene(scene);
    rtcReleaseDevice(dev);
    return std::chrono::duration<double>(t1 - t0).count();
}

}  // namespace anchor

#else

namespace anchor {
bool Available() { return false; }
Result UserBvh(const scenes::Scene&, int, int) { return {}; }
double SceneCommit(const scenes::Scene&, int, int) { return 0; }
}  // namespace anchor

#endif
