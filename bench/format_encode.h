// Re-encodes a float scene into any vertex format the builder decodes (benchmark input only).
#pragma once

#include <cstdint>
#include <vector>

#include "asval/builder/geometry_view.h"
#include "scenes.h"

namespace bench {

struct EncodedScene {
    std::vector<uint8_t> vertices;
    asval::builder::TriangleGeometryView view;
};

// Coordinates are first mapped into the format's range (norm formats: the scene box onto [-1,1]/[0,1]).
EncodedScene Encode(const scenes::Scene& s, VkFormat format);

}  // namespace bench
