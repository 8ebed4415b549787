#include "build_activity.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "asval/builder/build_input.h"
#include "asval/builder/classify.h"
#include "asval/builder/index_hash.h"
#include "asval/builder/vertex_format.h"

namespace asval {

namespace {

// The builder's views of a captured triangle or AABB geometry: the captured bytes with the parameters the copy
// left to apply. A triangle view carries the captured transform too (only the box scan reads it; classifying
// needs none: a transform does not change activity).
builder::TriangleGeometryView TriangleView(const CaptureLog& log, const CapturedGeometry& g) {
  builder::TriangleGeometryView view;
  view.vertexData = log.Bytes(g.data);
  view.vertexDataBytes = g.data.size;
  view.vertexFormat = g.vertex_format;
  view.vertexStride = g.vertex_stride;
  view.maxVertex = g.max_vertex;
  view.indexType = g.index_type;
  if (g.indices.present) {
    view.indexData = log.Bytes(g.indices);
    view.indexDataBytes = g.indices.size;
  }
  if (g.transform.present) {
    view.transformData = log.Bytes(g.transform);
    view.transformDataBytes = g.transform.size;
  }
  if (g.motion_data.present) {  // a motion build: activity and boxes over both times
    view.motionVertexData = log.Bytes(g.motion_data);
    view.motionVertexDataBytes = g.motion_data.size;
  }
  view.range = g.range;
  return view;
}

builder::AabbGeometryView AabbView(const CaptureLog& log, const CapturedGeometry& g) {
  builder::AabbGeometryView view;
  view.data = log.Bytes(g.data);
  view.dataBytes = g.data.size;
  view.stride = g.aabb_stride;
  view.range = g.range;
  return view;
}

// Set bits of a word, and its lowest set bit's index (bits != 0), without a library call (the build does not
// assume the popcnt instruction).
uint32_t PopCount64(uint64_t x) {
  x -= (x >> 1) & 0x5555555555555555ull;
  x = (x & 0x3333333333333333ull) + ((x >> 2) & 0x3333333333333333ull);
  x = (x + (x >> 4)) & 0x0f0f0f0f0f0f0f0full;
  return static_cast<uint32_t>((x * 0x0101010101010101ull) >> 56);
}
uint32_t CountTrailingZeros(uint64_t bits) { return static_cast<uint32_t>(__builtin_ctzll(bits)); }

// Whether any of `words` 32-bit words at `bytes` is not 0.
bool AnyBitSet(const uint8_t* bytes, std::size_t words) {
  uint64_t any = 0;
  std::size_t w = 0;
  for (; w + 2 <= words; w += 2) {
    uint64_t pair;
    std::memcpy(&pair, bytes + 4 * w, sizeof(pair));
    any |= pair;
  }
  if (w < words) {
    uint32_t last;
    std::memcpy(&last, bytes + 4 * w, sizeof(last));
    any |= last;
  }
  return any != 0;
}

// The record of a geometry the layer's dispatch classified on the device (CapturedGeometry::reduced): its bits as
// the builder would have set them, and the index hash combined from the dispatch's block hashes, as the builder
// computes it. False when a primitive could not be read (an index above maxVertex), as for the builder's unreadable
// primitives.
bool RecordReduced(const CaptureLog& log, const CapturedGeometry& g, builder::ActivityRecord* record,
                   builder::ClassifyResult* out) {
  const ReducedGeometry reduced = log.Reduced(g);
  const uint32_t n = reduced.count;
  record->primitiveCount = n;
  record->activeBits.assign((static_cast<std::size_t>(n) + 63) / 64, 0);
  record->hasIndexHash = false;
  record->indexHash = {};
  builder::ClassifyResult result;
  result.primitiveCount = n;
  const bool instances = g.type == VK_GEOMETRY_TYPE_INSTANCES_KHR;
  // 64 bits at a time, whatever the primitive count asks of the host: two of the device's little-endian words are
  // one word of the record, and a word with no bit set (the common case) costs a test.
  static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the device's bit arrays are the record's bytes");
  const std::size_t words = ReducedWords(n);
  const std::size_t words64 = record->activeBits.size();
  if (!instances && AnyBitSet(reduced.ArrayBytes(ReducedGeometry::kUnreadable), words)) return false;
  if (words != 0) std::memcpy(record->activeBits.data(), reduced.ArrayBytes(ReducedGeometry::kActive), 4 * words);
  uint32_t active = 0;
  for (const uint64_t bits : record->activeBits) active += bits == ~0ull ? 64 : PopCount64(bits);
  const uint8_t* undefined = reduced.ArrayBytes(ReducedGeometry::kUndefined);
  // Instances' second array is the transforms' (the warning reads it); a valid refit has no undefined vertex.
  if (!instances && AnyBitSet(undefined, words)) {
    for (std::size_t w = 0; w < words64; ++w) {
      uint64_t bits = 0;
      if (2 * w + 1 < words) {
        std::memcpy(&bits, undefined + 8 * w, 8);
      } else {
        std::memcpy(&bits, undefined + 8 * w, 4);
      }
      if (bits == 0) continue;
      if (result.undefinedNaN == 0) result.firstUndefined = static_cast<uint32_t>(64 * w) + CountTrailingZeros(bits);
      result.undefinedNaN += PopCount64(bits);
    }
  }
  if (g.type == VK_GEOMETRY_TYPE_TRIANGLES_KHR && g.index_type != VK_INDEX_TYPE_NONE_KHR) {
    if (!g.indices.present) return false;
    // The dispatch hashed each 64 triangles' indices where the build read them: the host combines one hash per
    // block, whatever the triangle count.
    const auto index_bytes = static_cast<uint64_t>(builder::IndexTypeBytes(g.index_type));
    builder::IndexHashCombiner combiner(index_bytes);
    combiner.AddHashes(log.Bytes(g.indices), static_cast<std::size_t>(g.indices.size / kReducedHashBytes));
    record->hasIndexHash = true;
    record->indexHash = combiner.Finish(3 * uint64_t{n} * index_bytes);
  }
  record->activeCount = active;
  result.active = active;
  result.inactive = n - active;
  *out = result;
  return true;
}

// Whether the layer's dispatch gathered the record of every pointer of a gathered array of instance pointers.
bool EveryPointerFollowed(const CaptureLog& log, const CapturedGeometry& g) {
  if (!g.pointers.present) return false;
  const uint8_t* pointers = log.Bytes(g.pointers);
  for (uint32_t k = 0; k < g.range.primitiveCount; ++k) {
    if (!FollowedInstancePointer(InstancePointer(pointers, k))) return false;
  }
  return true;
}

// The builder's view of one captured geometry; false when its bytes were not captured.
bool Classify(const CaptureLog& log, const CapturedGeometry& g, builder::ActivityRecord* record,
              builder::ClassifyResult* out) {
  if (g.range.primitiveCount == 0) {
    *record = builder::ActivityRecord{};
    return true;
  }
  if (!g.data.present) return false;
  if (g.reduced) return RecordReduced(log, g, record, out);
  builder::ClassifyResult result;
  if (g.type == VK_GEOMETRY_TYPE_TRIANGLES_KHR) {
    if (g.index_type != VK_INDEX_TYPE_NONE_KHR && !g.indices.present) return false;
    result = builder::ClassifyTriangles(TriangleView(log, g), record, nullptr, builder::ClassifyDetail::kActivity);
  } else if (g.type == VK_GEOMETRY_TYPE_INSTANCES_KHR) {
    // Arrays of pointers: their records, gathered, read as a plain array's (the same records give the same bits,
    // so an update compares with its source whichever layout each used); a record not followed is unknown.
    if (g.array_of_pointers && !EveryPointerFollowed(log, g)) return false;
    builder::InstanceGeometryView view;
    view.data = log.Bytes(g.data);
    view.dataBytes = g.data.size;
    view.range = g.range;
    result = builder::ClassifyInstances(view, record, nullptr);
  } else if (g.type == VK_GEOMETRY_TYPE_AABBS_KHR) {
    result = builder::ClassifyAabbs(AabbView(log, g), record, nullptr);
  } else {
    return false;
  }
  *out = result;
  // Primitives whose bytes the copy did not reach are recorded active: a guess. Unknown instead.
  return result.status == builder::ClassifyStatus::Ok && result.unreadable == 0 && !result.indexHashPartial;
}

// The builder's per-primitive boxes of one captured triangle or AABB geometry (exactly decoded, through the
// geometry's transform when it was captured), into `out`; false for other geometries.
bool PrimitiveBoxes(const CaptureLog& log, const CapturedGeometry& g, builder::BuildInput* out) {
  // Reduced on the device: no coordinates here (the capture copies whenever float_spacing is on).
  if (g.range.primitiveCount == 0 || !g.data.present || g.reduced) return false;
  constexpr bool kKeepDegenerate = true;  // kept, and skipped below by their zero size
  if (g.type == VK_GEOMETRY_TYPE_TRIANGLES_KHR) {
    builder::AppendTriangles(TriangleView(log, g), kKeepDegenerate, 0, out);
    return true;
  }
  if (g.type == VK_GEOMETRY_TYPE_AABBS_KHR) {
    builder::AppendAabbs(AabbView(log, g), kKeepDegenerate, 0, out);
    return true;
  }
  return false;
}

// Whether a primitive's box is so far out that float spacing there exceeds permille / 1000 of its size.
bool CoarselySpaced(const builder::PrimRef& box, uint32_t permille, float* magnitude, float* size) {
  float m = 0, extent = 0;
  for (int axis = 0; axis < 3; ++axis) {
    m = std::max({m, std::fabs(box.lo[axis]), std::fabs(box.hi[axis])});
    extent = std::max(extent, box.hi[axis] - box.lo[axis]);
  }
  if (!std::isfinite(m) || !std::isfinite(extent) || extent <= 0) return false;  // not a size to compare with
  *magnitude = m;
  *size = extent;
  return SpacingExceeds(m, extent, permille);
}

// The first NaN or infinite element of a geometry's captured transform, or -1 (none, or not captured).
int NonFiniteElement(const CaptureLog& log, const CapturedGeometry& g) {
  return g.transform.present ? FirstNonFiniteElement(log.Bytes(g.transform)) : -1;
}

}  // namespace

float FloatSpacingAt(float x) {
  const float a = std::fabs(x);
  return std::nextafter(a, INFINITY) - a;
}

bool SpacingExceeds(float magnitude, float size, uint32_t permille) {
  return static_cast<double>(FloatSpacingAt(magnitude)) * 1000.0 > static_cast<double>(permille) * size;
}

int FirstNonFiniteElement(const uint8_t* matrix) {
  if (AllFinite(matrix)) return -1;
  for (int k = 0; k < 12; ++k) {
    float value;
    std::memcpy(&value, matrix + 4 * k, sizeof(value));
    if (!std::isfinite(value)) return k;
  }
  return -1;
}

bool BuildActivity::NoActivePrimitive() const {
  if (status() != Status::kReady) return false;
  for (const builder::ActivityRecord& g : geometries_) {
    if (g.activeCount != 0) return false;
  }
  return true;
}

void BuildActivity::Fill(uint32_t spacing_permille) {
  if (status_.load(std::memory_order_relaxed) != Status::kPending) return;
  const CaptureLog* log = log_.get();
  const CapturedInfo* readable = log ? log->Readable(info_) : nullptr;
  if (!readable) {
    MarkUnknown();
    return;
  }
  const CapturedInfo& info = *readable;
  if (info.indirect && !info.indirect_geometry) {  // only its range infos were captured: what it built from is unknown
    MarkUnknown();
    return;
  }
  geometries_.resize(info.geometry_count);
  for (uint32_t j = 0; j < info.geometry_count; ++j) {
    builder::ClassifyResult result;
    CapturedGeometry executed;  // an indirect info's with its range as the device read it
    if (!ExecutedGeometry(*log, info, j, &executed) || !Classify(*log, executed, &geometries_[j], &result)) {
      geometries_.clear();
      undefined_.clear();
      MarkUnknown();
      return;
    }
    const int transform_element = NonFiniteElement(*log, executed);
    if (result.undefinedNaN != 0 || transform_element >= 0) {
      undefined_.push_back(UndefinedInput{j, result.undefinedNaN, result.firstUndefined, transform_element});
    }
  }
  if (spacing_permille != 0 && !info.indirect) ScanSpacing(*log, info, spacing_permille);  // indirect: reduced
  status_.store(Status::kReady, std::memory_order_release);
  log_.reset();
}

void BuildActivity::ScanSpacing(const CaptureLog& log, const CapturedInfo& info, uint32_t permille) {
  thread_local builder::BuildInput boxes;  // reused: a steady stream of frames allocates nothing
  for (uint32_t j = 0; j < info.geometry_count; ++j) {
    boxes.refs.clear();
    if (!PrimitiveBoxes(log, log.geometries[info.first_geometry + j], &boxes)) continue;
    CoarseSpacing found;
    found.geometry = j;
    for (const builder::PrimRef& box : boxes.refs) {
      float magnitude = 0, size = 0;
      const bool coarse = CoarselySpaced(box, permille, &magnitude, &size);
      if (size > 0 && (smallest_ == 0 || size < smallest_)) smallest_ = size;
      if (!coarse) continue;
      if (found.primitives++ == 0) {
        found.first_primitive = box.id;
        found.magnitude = magnitude;
        found.size = size;
      }
    }
    if (found.primitives != 0) coarse_.push_back(found);
  }
}

}  // namespace asval
