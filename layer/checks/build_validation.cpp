#include "build_validation.h"

#include "build_alignment.h"

namespace asval {

namespace {

// One line per rule family. Each family function covers all three build commands (BuildCommand::kind
// says which) and is skipped entirely when the enabled_checks setting leaves its family out.
struct BuildFamily {
  LayerSettingFlagBits family;
  bool (*validate)(const CheckContext& ctx, const BuildCommand& cmd);
};

constexpr BuildFamily kBuildFamilies[] = {
    {kCheckAlignment, &ValidateBuildAlignment},
};

}  // namespace

bool ValidateBuildCommand(const CheckContext& ctx, const BuildCommand& cmd) {
  bool skip = false;
  for (const BuildFamily& f : kBuildFamilies) {
    if (ctx.Enabled(f.family)) skip |= f.validate(ctx, cmd);
  }
  return skip;
}

}  // namespace asval
