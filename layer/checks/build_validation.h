#pragma once
// Runs every enabled rule family over one build command. Returns true when the app asked (a callback
// returned VK_TRUE) that the call not be passed down.
#include "build_command.h"
#include "check_context.h"

namespace asval {

bool ValidateBuildCommand(const CheckContext& ctx, const BuildCommand& cmd);

}  // namespace asval
