#include "build_activity.h"

#include <cmath>
#include <cstring>

#include "asval/builder/classify.h"

namespace asval {

namespace {

// The builder's view of one captured geometry; false when its bytes were not captured.
bool Classify(const CaptureLog& log, const CapturedGeometry& g, builder::ActivityRecord* record,
              builder::ClassifyResult* out) {
  if (g.range.primitiveCount == 0) {
    *record = builder::ActivityRecord{};
    return true;
  }
  if (!g.data.present) return false;
  builder::ClassifyResult result;
  if (g.type == VK_GEOMETRY_TYPE_TRIANGLES_KHR) {
    if (g.index_type != VK_INDEX_TYPE_NONE_KHR && !g.indices.present) return false;
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
    view.range = g.range;
    result = builder::ClassifyTriangles(view, record, nullptr);
  } else if (g.type == VK_GEOMETRY_TYPE_INSTANCES_KHR) {
    if (g.array_of_pointers) return false;  // the pointers only: the records they point to are not captured
    builder::InstanceGeometryView view;
    view.data = log.Bytes(g.data);
    view.dataBytes = g.data.size;
    view.range = g.range;
    result = builder::ClassifyInstances(view, record, nullptr);
  } else if (g.type == VK_GEOMETRY_TYPE_AABBS_KHR) {
    builder::AabbGeometryView view;
    view.data = log.Bytes(g.data);
    view.dataBytes = g.data.size;
    view.stride = g.aabb_stride;
    view.range = g.range;
    result = builder::ClassifyAabbs(view, record, nullptr);
  } else {
    return false;
  }
  *out = result;
  // Primitives whose bytes the copy did not reach are recorded active: a guess. Unknown instead.
  return result.status == builder::ClassifyStatus::Ok && result.unreadable == 0 && !result.indexHashPartial;
}

// The first NaN or infinite element of a geometry's captured transform, or -1 (none, or not captured).
int NonFiniteElement(const CaptureLog& log, const CapturedGeometry& g) {
  return g.transform.present ? FirstNonFiniteElement(log.Bytes(g.transform)) : -1;
}

}  // namespace

int FirstNonFiniteElement(const uint8_t* matrix) {
  for (int k = 0; k < 12; ++k) {
    float value;
    std::memcpy(&value, matrix + 4 * k, sizeof(value));
    if (!std::isfinite(value)) return k;
  }
  return -1;
}

void BuildActivity::Fill() {
  if (status_ != Status::kPending) return;
  const CaptureLog* log = log_.get();
  const CapturedInfo* readable = log ? log->Readable(info_) : nullptr;
  if (!readable) {
    MarkUnknown();
    return;
  }
  const CapturedInfo& info = *readable;
  if (info.indirect) {  // only its range infos were captured: what it built from is not known
    MarkUnknown();
    return;
  }
  geometries_.resize(info.geometry_count);
  for (uint32_t j = 0; j < info.geometry_count; ++j) {
    builder::ClassifyResult result;
    if (!Classify(*log, log->geometries[info.first_geometry + j], &geometries_[j], &result)) {
      geometries_.clear();
      undefined_.clear();
      MarkUnknown();
      return;
    }
    const int transform_element = NonFiniteElement(*log, log->geometries[info.first_geometry + j]);
    if (result.undefinedNaN != 0 || transform_element >= 0) {
      undefined_.push_back(UndefinedInput{j, result.undefinedNaN, result.firstUndefined, transform_element});
    }
  }
  status_ = Status::kReady;
  log_.reset();
}

}  // namespace asval
