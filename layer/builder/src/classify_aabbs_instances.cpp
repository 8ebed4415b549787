// AABB and instance classification (triangles are in classify_triangles.cpp).
#include "asval/builder/classify.h"
#include "format_traits.h"
#include "motion_instances.h"
#include "float_mode.h"

namespace asval::builder {
namespace {

using namespace detail;

constexpr uint64_t kInstanceBytes = 64;        // sizeof(VkAccelerationStructureInstanceKHR)
constexpr uint64_t kInstanceReferenceAt = 56;  // offsetof(..., accelerationStructureReference)

// Records one primitive's state into the running word / counters.
struct Recorder {
    ActivityRecord* record;
    uint8_t* states;
    uint64_t word = 0;
    uint32_t active = 0;
    void Put(uint32_t i, uint8_t state) {
        const uint64_t bit = state & kStateActive;
        active += uint32_t(bit);
        word |= bit << (i & 63);
        if ((i & 63) == 63) {
            if (record) record->activeBits[i >> 6] = word;
            word = 0;
        }
        if (states) states[i] = state;
    }
    void Finish(uint32_t n, ClassifyResult& r) {
        if (record && (n & 63) != 0) record->activeBits[n >> 6] = word;
        r.active = active;
        r.inactive = n - active;
        if (record) {
            record->primitiveCount = n;
            record->activeCount = active;
            record->hasIndexHash = false;
            record->indexHash = {};
        }
    }
    static Recorder Start(ActivityRecord* record, uint8_t* states, uint32_t n) {
        if (record) record->activeBits.resize((size_t(n) + 63) / 64);
        return Recorder{record, states};
    }
};

void NoteUnreadable(ClassifyResult& r, uint32_t i) {
    ++r.unreadable;
    if (r.firstUnreadable == UINT32_MAX) r.firstUnreadable = i;
}

// Motion instances (VK_NV_ray_tracing_motion_blur): "An inactive instance is one whose acceleration
// structure reference is 0", read from the reference field of the record's own type. Nothing else (mask,
// NaN in either transform) changes activity. Records that cannot be read are recorded active.
ClassifyResult ClassifyMotionInstances(const InstanceGeometryView& view, ActivityRecord* record, uint8_t* states) {
    ClassifyResult r;
    const uint32_t n = view.range.primitiveCount;
    r.primitiveCount = n;
    Recorder rec = Recorder::Start(record, states, n);
    for (uint32_t i = 0; i < n; ++i) {
        const MotionRecord m = LocateMotionInstance(view, i);
        if (m.status != MotionRecord::Ok) {
            if (m.status == MotionRecord::NullPointer) ++r.nullInstancePointer;
            if (m.status == MotionRecord::InvalidType) {
                ++r.invalidMotionType;
                if (r.firstInvalidMotionType == UINT32_MAX) r.firstInvalidMotionType = i;
            }
            NoteUnreadable(r, i);
            rec.Put(i, kStateActive | kStateUnreadable);
            continue;
        }
        r.nonZeroMotionFlags += m.flags != 0;
        rec.Put(i, MotionReference(m) != 0 ? kStateActive : 0);
    }
    rec.Finish(n, r);
    return r;
}

}  // namespace

ClassifyResult ClassifyAabbs(const AabbGeometryView& view, ActivityRecord* record, uint8_t* states) {
    const detail::FloatModeGuard mode;
    ClassifyResult r;
    const uint32_t n = view.range.primitiveCount;
    r.primitiveCount = n;
    Recorder rec = Recorder::Start(record, states, n);
    const auto* base = static_cast<const uint8_t*>(view.data);
    const uint64_t bytes = base ? view.dataBytes : 0;
    for (uint32_t i = 0; i < n; ++i) {
        const uint64_t off = uint64_t(view.range.primitiveOffset) + uint64_t(i) * view.stride;
        if (off > bytes || bytes - off < 24) {
            NoteUnreadable(r, i);
            rec.Put(i, kStateActive | kStateUnreadable);
            continue;
        }
        const uint8_t* p = base + off;
        uint32_t b[6];
        for (int c = 0; c < 6; ++c) b[c] = LoadU32(p + 4 * c);
        if (F32BitsNaN(b[0])) {  // minX NaN: inactive
            rec.Put(i, 0);
            continue;
        }
        uint8_t state = kStateActive;
        bool otherNaN = false;
        for (int c = 1; c < 6; ++c) otherNaN |= F32BitsNaN(b[c]);
        if (otherNaN) {
            state |= kStateUndefined;
            ++r.undefinedNaN;
            if (r.firstUndefined == UINT32_MAX) r.firstUndefined = i;
        }
        float f[6];
        for (int c = 0; c < 6; ++c) f[c] = LoadF32(p + 4 * c);
        // IEEE comparisons: NaN never equal, never greater (this file is never built with -ffast-math).
        if (f[0] == f[3] && f[1] == f[4] && f[2] == f[5]) {
            state |= kStateDegenerate;
            ++r.degenerate;
        }
        if (f[0] > f[3] || f[1] > f[4] || f[2] > f[5]) {
            state |= kStateInvalidAabb;
            ++r.invalidAabb;
            if (r.firstInvalidAabb == UINT32_MAX) r.firstInvalidAabb = i;
        }
        rec.Put(i, state);
    }
    rec.Finish(n, r);
    return r;
}

ClassifyResult ClassifyInstances(const InstanceGeometryView& view, ActivityRecord* record, uint8_t* states) {
    const detail::FloatModeGuard mode;
    if (view.motionInstances) return ClassifyMotionInstances(view, record, states);
    ClassifyResult r;
    const uint32_t n = view.range.primitiveCount;
    r.primitiveCount = n;
    Recorder rec = Recorder::Start(record, states, n);
    const auto* base = static_cast<const uint8_t*>(view.data);
    const uint64_t bytes = base ? view.dataBytes : 0;
    const uint64_t elem = view.arrayOfPointers ? sizeof(const void*) : kInstanceBytes;
    for (uint32_t i = 0; i < n; ++i) {
        const uint64_t off = uint64_t(view.range.primitiveOffset) + uint64_t(i) * elem;
        if (off > bytes || bytes - off < elem) {
            NoteUnreadable(r, i);
            rec.Put(i, kStateActive | kStateUnreadable);
            continue;
        }
        const uint8_t* inst = base + off;
        if (view.arrayOfPointers) {
            const void* ptr;
            std::memcpy(&ptr, inst, sizeof ptr);
            if (!ptr) {
                ++r.nullInstancePointer;
                NoteUnreadable(r, i);
                rec.Put(i, kStateActive | kStateUnreadable);
                continue;
            }
            inst = static_cast<const uint8_t*>(ptr);
        }
        uint64_t reference;
        std::memcpy(&reference, inst + kInstanceReferenceAt, 8);
        rec.Put(i, reference != 0 ? kStateActive : 0);
    }
    rec.Finish(n, r);
    return r;
}

}  // namespace asval::builder
