#pragma once
// The scene's command line.
#include <cstdint>
#include <string>
#include <vector>

namespace scene {

struct FaultInfo;

struct SceneOptions {
  uint32_t frames = 4;
  uint32_t instances = 2000;
  uint32_t refits = 0;  // --refits: extra structures refit per frame, one call each
  uint32_t width = 256;
  uint32_t height = 256;
  std::string out;                   // PNG path; empty: no image written
  const FaultInfo* fault = nullptr;  // --inject
  bool static_scene = false;  // --static: structures built once, frames only trace rays
  // --checkpoints: frame counts (ascending, at most `frames`) after which memory and frame times are printed.
  std::vector<uint32_t> checkpoints;
  bool list_faults = false;
  bool help = false;
};

// Returns false (with a message in *error) on a malformed command line.
bool ParseOptions(int argc, char** argv, SceneOptions* options, std::string* error);
const char* Usage();

}  // namespace scene
