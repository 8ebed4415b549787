#pragma once
// Runs every enabled rule family over one build command. Returns true when the app asked (a callback
// returned VK_TRUE) that the call not be passed down.
#include "build_command.h"
#include "check_context.h"

namespace asval {

struct CheckThreadData;

bool ValidateBuildCommand(const CheckContext& ctx, const BuildCommand& cmd);
// The same with the calling thread's data, leased by the hook for the whole call (check_thread_data.h).
bool ValidateBuildCommand(const CheckContext& ctx, const BuildCommand& cmd, CheckThreadData& thread);

}  // namespace asval
