#include "location.h"

namespace asval {

std::string Location::Path() const {
  std::string path;
  for (int i = 0; i < depth_; ++i) {
    if (i) path.push_back('.');
    path.append(elements_[i].field);
    if (elements_[i].index != kNoIndex) {
      path.push_back('[');
      path.append(std::to_string(elements_[i].index));
      path.push_back(']');
    }
  }
  if (truncated_) path.append(".(...)");
  return path;
}

}  // namespace asval
