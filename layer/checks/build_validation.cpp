#include "build_validation.h"

#include <iterator>
#include <utility>

#include "build_alignment.h"
#include "build_features.h"
#include "build_handles.h"
#include "build_host.h"
#include "build_memory_pass.h"
#include "build_ranges.h"
#include "build_structure.h"
#include "check_thread_data.h"
#include "history_host.h"
#include "resolved_build.h"

namespace asval {

namespace {

// One line per rule family. Each family function covers all three build commands (BuildCommand::kind
// says which) and is skipped entirely when the enabled_checks setting leaves its family out. Families that
// need each info's structures, sizes or buffers read them from the command's resolved view, looked up once.
struct BuildFamily {
  LayerSettingFlagBits family;
  bool (*validate)(const CheckContext& ctx, const BuildCommand& cmd, const ResolvedBuild& resolved);
  bool host_only = false;  // has nothing to say about device builds (not called for them)
};

// For the families that need nothing resolved.
template <bool (*validate)(const CheckContext&, const BuildCommand&)>
bool Unresolved(const CheckContext& ctx, const BuildCommand& cmd, const ResolvedBuild&) {
  return validate(ctx, cmd);
}

constexpr BuildFamily kBuildFamilies[] = {
    {kCheckFeatures, &Unresolved<&ValidateBuildFeatures>},
    {kCheckHandles, &ValidateBuildHandles},
    {kCheckStructure, &ValidateBuildStructure},
    {kCheckStructure, &ValidateBuildRanges},
    {kCheckAlignment, &ValidateBuildAlignment},
    {kCheckHistory, &Unresolved<&ValidateBuildHistory>, true},  // device builds: at submission
    // Addresses and aliasing share one pass over the resolved sizes, destinations and scratch.
    {kCheckAddressesOrAliasing, &ValidateBuildMemory},
    {kCheckHost, &ValidateBuildHost, true},
};

// The table walked at compile time: each family is a direct call behind its settings test (a loop over the
// table made an indirect call per family and reloaded each entry).
template <std::size_t... k>
bool RunFamilies(const CheckContext& ctx, const BuildCommand& cmd, const ResolvedBuild& resolved,
                 std::index_sequence<k...>) {
  bool skip = false;
  const auto run = [&](const BuildFamily& f) {
    if (ctx.Enabled(f.family) && (!f.host_only || cmd.is_host())) skip |= f.validate(ctx, cmd, resolved);
  };
  (run(kBuildFamilies[k]), ...);
  return skip;
}

}  // namespace

bool ValidateBuildCommand(const CheckContext& ctx, const BuildCommand& cmd, CheckThreadData& thread) {
  const ResolvedBuild resolved(ctx, cmd, thread);
  return RunFamilies(ctx, cmd, resolved, std::make_index_sequence<std::size(kBuildFamilies)>());
}

bool ValidateBuildCommand(const CheckContext& ctx, const BuildCommand& cmd) {
  const CheckThreadLease thread;
  return ValidateBuildCommand(ctx, cmd, thread.data());
}

}  // namespace asval
