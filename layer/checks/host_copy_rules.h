#pragma once
// The host copies' own rules (family "host"), at the call:
//   deferredOperation-03678   the deferred operation has no earlier host command still running (as for host builds,
//                             build_host.h; known for host builds and copies the layer saw deferred)
//   buffer-03727 / 03728 / 03730 / 03731 / 03733   the structures a host copy reads or writes, and those a host
//                             property write queries, are on buffers bound to host-visible memory (host_memory.h)
//   buffer-03780 / 03781 / 03782 / 03783 / 03784   ... to memory not allocated with multiple instances
//   vkCopyMemoryToAccelerationStructureKHR   pInfo-03729 src.hostAddress a host pointer (null is not), pInfo-03750
//                                            it is aligned to 16 bytes
//   vkCopyAccelerationStructureToMemoryKHR   pInfo-03732 dst.hostAddress a host pointer (null is not), pInfo-03751
//                                            it is aligned to 16 bytes
#include <vulkan/vulkan.h>

#include "check_context.h"

namespace asval {

// function: vkCopyAccelerationStructureKHR, vkCopyAccelerationStructureToMemoryKHR or
// vkCopyMemoryToAccelerationStructureKHR.
bool ValidateHostCopyDeferred(const CheckContext& ctx, const char* function, VkDeferredOperationKHR deferred);
bool ValidateHostCopyStructures(const CheckContext& ctx, const VkCopyAccelerationStructureInfoKHR& info);
bool ValidateHostCopyToMemory(const CheckContext& ctx, const VkCopyAccelerationStructureToMemoryInfoKHR& info);
bool ValidateHostCopyMemoryTo(const CheckContext& ctx, const VkCopyMemoryToAccelerationStructureInfoKHR& info);

bool ValidateHostPropertyStructures(const CheckContext& ctx, uint32_t count,
                                    const VkAccelerationStructureKHR* structures);

}  // namespace asval
