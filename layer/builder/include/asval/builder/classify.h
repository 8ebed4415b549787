// Classification of primitives as the spec defines it ("Inactive Primitives and Instances", "Degenerate
// Primitives and Instances"). Decisions on the spec's open questions (docs/builder.md, "Decisions"):
//  * inactive: raw-bit NaN test of the *source* X component (any NaN encoding), before any arithmetic;
//    formats without NaN (SNORM/UNORM) are always active.
//  * degenerate: tested on the decoded, untransformed components, by value (+0 == -0; SNORM codes -2^(b-1)
//    and -2^(b-1)+1 both decode to -1 and are equal). NaN compares unequal to everything.
//  * a NaN in the transform does not make a triangle inactive; it is counted for a warning.
//  * NaN in Y/Z (or an AABB's non-minX component) with X not NaN: active, counted as undefined input.
#pragma once

#include <cstdint>

#include "asval/builder/activity_record.h"
#include "asval/builder/geometry_view.h"

namespace asval::builder {

// Per-primitive state bits (optional output, one byte per primitive; the layer normally passes none).
enum PrimitiveState : uint8_t {
    kStateActive = 1u << 0,
    kStateDegenerate = 1u << 1,   // spec-degenerate (only set on active primitives)
    kStateSameIndex = 1u << 2,    // two index values equal: always discardable (active primitives only)
    kStateUndefined = 1u << 3,    // NaN outside X / minX while X is not NaN: behaviour undefined
    kStateUnreadable = 1u << 4,   // its data lies outside the bytes provided: not classified (recorded active)
    kStateInvalidAabb = 1u << 5,  // min > max on some axis (VUID-VkAabbPositionsKHR-minX-03546..03548)
};

enum class ClassifyStatus : uint8_t {
    Ok,
    UnsupportedFormat,     // vertexFormat not decodable: nothing classified
    UnsupportedIndexType,  // nothing classified
};

struct ClassifyResult {
    ClassifyStatus status = ClassifyStatus::Ok;
    uint32_t primitiveCount = 0;
    uint32_t active = 0;
    uint32_t inactive = 0;
    uint32_t degenerate = 0;
    uint32_t sameIndex = 0;
    uint32_t undefinedNaN = 0;
    uint32_t unreadable = 0;
    uint32_t invalidAabb = 0;
    uint32_t overMaxVertex = 0;       // triangles reading a vertex above maxVertex (VUID 10774 / 10775)
    uint32_t nullInstancePointer = 0; // arrayOfPointers entries that are null (counted unreadable too)
    // Motion instances: a type outside STATIC / MATRIX_MOTION / SRT_MOTION (VUID-VkAccelerationStructure-
    // MotionInstanceNV-type-parameter): its layout is unknown, so it is counted unreadable too (active).
    uint32_t invalidMotionType = 0;
    uint32_t firstInvalidMotionType = UINT32_MAX;
    uint32_t nonZeroMotionFlags = 0;  // plain motion records with flags != 0 (...-flags-zerobitmask)
    bool transformHasNaN = false;     // a NaN in the 3x4 transform (warning; activity unchanged)
    bool transformUnreadable = false; // transform pointer set but its 48 bytes at transformOffset not provided
    bool indexHashPartial = false;    // index bytes missing: the hash covers only what was provided
    // First primitive of each kind, or UINT32_MAX: the layer names it in the message.
    uint32_t firstUndefined = UINT32_MAX;
    uint32_t firstUnreadable = UINT32_MAX;
    uint32_t firstOverMaxVertex = UINT32_MAX;
    uint32_t firstInvalidAabb = UINT32_MAX;
};

// Each function fills `record` (activity bits, counts, and for indexed triangles the index hash) and,
// when `states` is not null, one PrimitiveState byte per primitive. `record` may be null to get counts only.
// The record's storage is reused across calls when large enough.
//
// What ClassifyTriangles counts. kActivity: what an update's rules compare, exactly: the record, active,
// inactive, undefinedNaN, unreadable, their first primitives and the transform and index-hash fields; degenerate,
// sameIndex and overMaxVertex stay 0. It lets the common case (every triangle readable, no NaN in any vertex the
// triangles can read) skip the per-triangle loop: one pass over the indices and one over those vertices.
enum class ClassifyDetail : uint8_t { kFull, kActivity };
ClassifyResult ClassifyTriangles(const TriangleGeometryView& view, ActivityRecord* record, uint8_t* states,
                                 ClassifyDetail detail = ClassifyDetail::kFull);
ClassifyResult ClassifyAabbs(const AabbGeometryView& view, ActivityRecord* record, uint8_t* states);
// Instances: active iff accelerationStructureReference != 0. Mask 0 is active. Degenerate instances (BLAS
// without active primitives) need the BLAS records: see build_input.h.
// Motion instances (view.motionInstances): the same rule on the reference field of the record's type
// (static, matrix or SRT); a NaN anywhere in a motion transform does not change activity (the spec's
// inactive rule for instances names only the reference).
// Motion triangles (view.motionVertexData): inactive iff the X component of any of the six vertices (three
// at time 0, three at time 1) is NaN; undefined-input iff a Y/Z is NaN at either time and no X is;
// degenerate iff degenerate at *every* time in [0, 1], i.e. one clause of the spec's definition (a vertex
// pair identical, or all three sharing the same two axes) holds at time 0 and at time 1 (see
// motion_triangles.cpp); unreadable iff either time's data is missing.
ClassifyResult ClassifyInstances(const InstanceGeometryView& view, ActivityRecord* record, uint8_t* states);

}  // namespace asval::builder
