#pragma once
// refit_frames' command line: how many bottom-level structures are refit per frame, of how many triangles,
// recorded as one vkCmdBuildAccelerationStructuresKHR each or as one call of all of them, for how many frames.
#include <cstdint>
#include <string>

namespace refit {

enum class Shape {
  kCalls,    // N calls of one info each (engines that refit each object where they animate it)
  kOneCall,  // one call of N infos
};

struct RefitOptions {
  uint32_t structures = 100;
  uint32_t triangles = 1024;
  Shape shape = Shape::kCalls;
  uint32_t frames = 100;  // measured frames
  // Refit frames run before the measured ones: drivers compile their update pipelines at first use.
  uint32_t warmup = 2;
  bool help = false;
};

const char* ShapeName(Shape shape);
// Returns false (with a message in *error) on a malformed command line.
bool ParseRefitOptions(int argc, char** argv, RefitOptions* options, std::string* error);
const char* RefitUsage();

}  // namespace refit
