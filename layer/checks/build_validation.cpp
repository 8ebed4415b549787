#include "build_validation.h"

#include "build_alignment.h"
#include "build_features.h"
#include "build_handles.h"
#include "build_host.h"
#include "build_memory_pass.h"
#include "build_ranges.h"
#include "build_structure.h"
#include "history_host.h"

namespace asval {

namespace {

// One line per rule family. Each family function covers all three build commands (BuildCommand::kind
// says which) and is skipped entirely when the enabled_checks setting leaves its family out.
struct BuildFamily {
  LayerSettingFlagBits family;
  bool (*validate)(const CheckContext& ctx, const BuildCommand& cmd);
};

constexpr BuildFamily kBuildFamilies[] = {
    {kCheckFeatures, &ValidateBuildFeatures},
    {kCheckHandles, &ValidateBuildHandles},
    {kCheckStructure, &ValidateBuildStructure},
    {kCheckStructure, &ValidateBuildRanges},
    {kCheckAlignment, &ValidateBuildAlignment},
    {kCheckHistory, &ValidateBuildHistory},  // host builds only; device builds are checked at submission
    // Addresses and aliasing share one pass: each info's sizes, destination and scratch are looked up once.
    {kCheckAddressesOrAliasing, &ValidateBuildMemory},
    {kCheckHost, &ValidateBuildHost},
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
