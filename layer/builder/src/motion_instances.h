// Private: reading VK_NV_ray_tracing_motion_blur instance records and their conservative boxes.
#pragma once

#include <cstdint>

#include "asval/builder/geometry_view.h"

namespace asval::builder::detail {

// VkAccelerationStructureMotionInstanceTypeNV values.
enum class MotionKind : uint32_t { Static = 0, Matrix = 1, Srt = 2 };

// Where instance i's record lies (after primitiveOffset, stride, pointer decoding and the bounds checks).
struct MotionRecord {
    enum Status : uint8_t { Ok, Unreadable, NullPointer, InvalidType } status = Unreadable;
    MotionKind kind = MotionKind::Static;
    const uint8_t* body = nullptr;  // the Instance / MatrixMotionInstance / SRTMotionInstance structure
    uint32_t flags = 0;             // VkAccelerationStructureMotionInstanceNV::flags (plain arrays only)
};

MotionRecord LocateMotionInstance(const InstanceGeometryView& view, uint32_t i);
uint64_t MotionReference(const MotionRecord& rec);  // rec.status == Ok

// Conservative box over every time in [0, 1] of the instance's image of the BLAS box [blasLo, blasHi]
// (degenerate: of the instance origin, the point 0). NaN never reaches the output: affected bounds are
// infinite. Argument for each kind in motion_instances.cpp.
void MotionInstanceBox(const MotionRecord& rec, const float blasLo[3], const float blasHi[3], bool degenerate,
                       float lo[3], float hi[3]);

}  // namespace asval::builder::detail
