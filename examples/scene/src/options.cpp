#include "options.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <utility>

#include "faults.h"

namespace scene {

namespace {

bool ParseCount(const char* text, uint32_t min, uint32_t max, uint32_t* value) {
  char* end = nullptr;
  const unsigned long v = std::strtoul(text, &end, 10);
  if (!*text || *end || v < min || v > max) return false;
  *value = static_cast<uint32_t>(v);
  return true;
}

// "100,1000,10000": ascending counts of 1..100000.
bool ParseCheckpoints(const char* text, std::vector<uint32_t>* out) {
  out->clear();
  std::string list = text;
  std::size_t begin = 0;
  while (begin <= list.size()) {
    const std::size_t comma = std::min(list.find(',', begin), list.size());
    uint32_t n = 0;
    if (!ParseCount(list.substr(begin, comma - begin).c_str(), 1, 100000, &n)) return false;
    if (!out->empty() && n <= out->back()) return false;
    out->push_back(n);
    begin = comma + 1;
  }
  return true;
}

bool Fail(std::string* error, std::string message) {
  *error = std::move(message);
  return false;
}

}  // namespace

const char* Usage() {
  return "usage: asval_scene [--frames N] [--instances N] [--size WxH] [--static] [--out FILE.png] [--inject FAULT]\n"
         "                   [--checkpoints N,N,...] [--refits N]\n"
         "       asval_scene --list-faults\n"
         "Renders an animated ray-traced scene without a window (any device with VK_KHR_acceleration_structure\n"
         "and VK_KHR_ray_tracing_pipeline). Layers come from the environment (VK_INSTANCE_LAYERS).\n"
         "  --frames N      frames to render (default 4)\n"
         "  --instances N   instances in the top-level structure, the ground included (default 2000)\n"
         "  --size WxH      image size (default 256x256)\n"
         "  --static        build the structures in frame 0 only; later frames only trace rays (no animation,\n"
         "                  refit or top-level update)\n"
         "  --out FILE      write the last frame as PNG\n"
         "  --inject FAULT  after the frames, commit one rule violation (see --list-faults), with asval's protect\n"
         "                  setting on (VkLayerSettingsCreateInfoEXT)\n"
         "  --checkpoints N,N,...  after each of these frame counts, print the process's resident memory (now and\n"
         "                  peak) and the wall time per frame of the 100 frames before (bench/longrun)\n"
         "  --refits N      refit N more bottom-level structures every frame (copies of the blob, not traced), each\n"
         "                  with its own vkCmdBuildAccelerationStructuresKHR, as engines refit many deforming\n"
         "                  objects (default 0)\n"
         "  --list-faults   print each fault with the VUID it must trigger\n";
}

bool ParseOptions(int argc, char** argv, SceneOptions* o, std::string* error) {
  for (int i = 1; i < argc; ++i) {
    const char* a = argv[i];
    const bool has_value = i + 1 < argc;
    if (std::strcmp(a, "--help") == 0 || std::strcmp(a, "-h") == 0) {
      o->help = true;
    } else if (std::strcmp(a, "--static") == 0) {
      o->static_scene = true;
    } else if (std::strcmp(a, "--list-faults") == 0) {
      o->list_faults = true;
    } else if (std::strcmp(a, "--frames") == 0 && has_value) {
      if (!ParseCount(argv[++i], 1, 100000, &o->frames)) return Fail(error, "--frames: expected 1..100000");
    } else if (std::strcmp(a, "--instances") == 0 && has_value) {
      if (!ParseCount(argv[++i], 2, 1000000, &o->instances)) return Fail(error, "--instances: expected 2..1000000");
    } else if (std::strcmp(a, "--refits") == 0 && has_value) {
      if (!ParseCount(argv[++i], 0, 100000, &o->refits)) return Fail(error, "--refits: expected 0..100000");
    } else if (std::strcmp(a, "--size") == 0 && has_value) {
      const std::string s = argv[++i];
      const size_t x = s.find('x');
      if (x == std::string::npos || !ParseCount(s.substr(0, x).c_str(), 1, 8192, &o->width) ||
          !ParseCount(s.substr(x + 1).c_str(), 1, 8192, &o->height)) {
        return Fail(error, "--size: expected WxH, e.g. 256x256");
      }
    } else if (std::strcmp(a, "--out") == 0 && has_value) {
      o->out = argv[++i];
    } else if (std::strcmp(a, "--checkpoints") == 0 && has_value) {
      if (!ParseCheckpoints(argv[++i], &o->checkpoints)) {
        return Fail(error, "--checkpoints: expected ascending frame counts separated by commas, e.g. 100,1000");
      }
    } else if (std::strcmp(a, "--inject") == 0 && has_value) {
      o->fault = FindFault(argv[++i]);
      if (!o->fault) return Fail(error, std::string("--inject: unknown fault '") + argv[i] + "' (see --list-faults)");
    } else {
      return Fail(error, std::string("unknown or incomplete argument '") + a + "'");
    }
  }
  if (!o->checkpoints.empty() && o->checkpoints.back() > o->frames) {
    return Fail(error, "--checkpoints: " + std::to_string(o->checkpoints.back()) + " is past --frames");
  }
  return true;
}

}  // namespace scene
