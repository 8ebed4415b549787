#pragma once
// Where in a call's parameters a finding is, e.g. pInfos[1].pGeometries[0].geometry.triangles.vertexData.
// A Location is a small value (a fixed array of path elements, no heap, no pointers to other Locations, so
// chaining temporaries is safe). It is only turned into text when something is reported, so the hot path
// formats nothing.
#include <cstdint>
#include <string>

namespace asval {

class Location {
 public:
  static constexpr int64_t kNoIndex = -1;
  static constexpr int kMaxDepth = 8;

  // The root: the command itself, e.g. "vkCmdBuildAccelerationStructuresKHR".
  explicit Location(const char* function) : function_(function) {}

  // Copies only the elements in use: a root Location costs three stores, which matters because every
  // intercepted call builds one whether or not anything is reported.
  Location(const Location& other)
      : function_(other.function_), depth_(other.depth_), truncated_(other.truncated_) {
    for (int i = 0; i < depth_; ++i) elements_[i] = other.elements_[i];
  }
  Location& operator=(const Location&) = delete;

  // A field of this location, optionally indexed: loc.Field("pInfos", i).Field("scratchData").
  Location Field(const char* field, int64_t index = kNoIndex) const {
    Location child = *this;
    if (child.depth_ < kMaxDepth) {
      child.elements_[child.depth_++] = Element{field, index};
    } else {
      child.truncated_ = true;  // deeper than any Vulkan parameter path; shown as "..."
    }
    return child;
  }

  const char* Function() const { return function_; }
  // The dotted path without the function, e.g. "pInfos[1].scratchData.deviceAddress"; empty at the root.
  std::string Path() const;

 private:
  struct Element {
    const char* field;
    int64_t index;
  };

  const char* function_;
  Element elements_[kMaxDepth];  // only [0, depth_) is ever read
  int depth_ = 0;
  bool truncated_ = false;
};

}  // namespace asval
