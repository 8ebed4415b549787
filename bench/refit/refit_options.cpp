#include "refit_options.h"

#include <cstdlib>
#include <cstring>

namespace refit {

namespace {

bool ParseCount(const char* text, uint32_t min, uint32_t max, uint32_t* value) {
  char* end = nullptr;
  const unsigned long v = std::strtoul(text, &end, 10);
  if (!*text || *end || v < min || v > max) return false;
  *value = static_cast<uint32_t>(v);
  return true;
}

bool Fail(std::string* error, const char* message) {
  *error = message;
  return false;
}

}  // namespace

const char* ShapeName(Shape shape) { return shape == Shape::kCalls ? "calls" : "one-call"; }

const char* RefitUsage() {
  return "usage: refit_frames [--structures N] [--triangles T] [--shape calls|one-call] [--frames F] [--warmup W]\n"
         "Each frame: a compute shader moves the vertices of N bottom-level structures, they are refit in place\n"
         "(MODE_UPDATE, src == dst, each with its own scratch slice), then one top-level structure over them is\n"
         "updated. Layers come from VK_INSTANCE_LAYERS. Prints per-frame means of the measured frames: CPU record\n"
         "time, submit+wait time, GPU time (timestamp queries) and frame time.\n"
         "  --structures N  bottom-level structures refit per frame (default 100)\n"
         "  --triangles T   triangles per structure (default 1024)\n"
         "  --shape S       calls: N vkCmdBuildAccelerationStructuresKHR of one info each (default);\n"
         "                  one-call: one call of N infos\n"
         "  --frames F      measured frames (default 100)\n"
         "  --warmup W      refit frames before the measured ones (default 2)\n";
}

bool ParseRefitOptions(int argc, char** argv, RefitOptions* o, std::string* error) {
  for (int i = 1; i < argc; ++i) {
    const char* a = argv[i];
    const bool has_value = i + 1 < argc;
    if (std::strcmp(a, "--help") == 0 || std::strcmp(a, "-h") == 0) {
      o->help = true;
    } else if (std::strcmp(a, "--structures") == 0 && has_value) {
      if (!ParseCount(argv[++i], 1, 100000, &o->structures)) return Fail(error, "--structures: expected 1..100000");
    } else if (std::strcmp(a, "--triangles") == 0 && has_value) {
      if (!ParseCount(argv[++i], 1, 1000000, &o->triangles)) return Fail(error, "--triangles: expected 1..1000000");
    } else if (std::strcmp(a, "--frames") == 0 && has_value) {
      if (!ParseCount(argv[++i], 1, 1000000, &o->frames)) return Fail(error, "--frames: expected 1..1000000");
    } else if (std::strcmp(a, "--warmup") == 0 && has_value) {
      if (!ParseCount(argv[++i], 0, 1000, &o->warmup)) return Fail(error, "--warmup: expected 0..1000");
    } else if (std::strcmp(a, "--shape") == 0 && has_value) {
      const char* s = argv[++i];
      if (std::strcmp(s, "calls") == 0) {
        o->shape = Shape::kCalls;
      } else if (std::strcmp(s, "one-call") == 0) {
        o->shape = Shape::kOneCall;
      } else {
        return Fail(error, "--shape: expected calls or one-call");
      }
    } else {
      *error = std::string("unknown or incomplete argument '") + a + "'";
      return false;
    }
  }
  return true;
}

}  // namespace refit
