#pragma once
// Commits one rule violation in the running scene (after its frames), then waits for the GPU.
#include "faults.h"
#include "scene.h"

namespace scene {

void InjectFault(Scene& scene, const FaultInfo& fault);

}  // namespace scene
