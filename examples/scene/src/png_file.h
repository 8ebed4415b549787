#pragma once
// Writes packed RGBA8 pixels (as the ray generation shader stores them) to a PNG file with libpng.
#include <cstdint>
#include <string>

namespace scene {

// Throws std::runtime_error on failure. The file holds no time stamp, so equal pixels give equal bytes.
void WritePng(const std::string& path, const uint32_t* rgba, uint32_t width, uint32_t height);

}  // namespace scene
