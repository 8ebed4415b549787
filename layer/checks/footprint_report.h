#pragma once
// ASVAL-Layer-Footprint: what the layer holds on a device when it is destroyed (layer/state/footprint.h), with
// the peaks the growing containers kept: one information message, so that a long run shows whether the layer's
// memory stayed flat (bench/longrun, docs/reliability.md).
#include <vulkan/vulkan.h>

#include <string>

#include "footprint.h"
#include "reporter.h"

namespace asval {

// The layer-specific id of the footprint message (info, at vkDestroyDevice).
inline constexpr const char kLayerFootprintId[] = "ASVAL-Layer-Footprint";

// The message's text: `name=value` pairs separated by spaces after a sentence saying what they are, so that
// scripts read them back (bench/longrun/run_longrun.py).
std::string FormatFootprint(const LayerFootprint& f);
void ReportFootprint(const LayerFootprint& f, Reporter& reporter, VkDevice device);

}  // namespace asval
