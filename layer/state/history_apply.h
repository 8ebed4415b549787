#pragma once
// How each operation changes the histories once it executes (the checks against the history *before* the
// operation are in layer/checks/update_rules.cpp). Call with the store's lock held.
#include <vulkan/vulkan.h>

#include <optional>

#include "device_state.h"

namespace asval {

// The VkDeviceMemory bytes a structure occupies (its buffer's binding, offset and size); nullopt when the
// structure, its buffer or the binding is unknown.
std::optional<MemorySpan> AccelerationStructureSpan(const DeviceState& state, VkAccelerationStructureKHR as);

// Applies one operation of `batch` to the histories in `state.history.store` (the caller counts it in
// store.ops_applied, once per batch: one atomic add, not one per operation). txn (may be null) collects the
// changes so that a skipped or failed submission can be rolled back. captures (may be null: host operations,
// which capture nothing) collects what the submission's captured builds ask for once it completes: their
// activity, and the updates to compare with their sources'.
// Throws std::bad_alloc when the layer's allocation fails (the test hook's state_apply too); the callers catch it
// where the state write began (HistorySubmission::Apply, the host commands' ApplyNow) and make every structure's
// history unknown, counted (failure_counters.h).
void ApplyOp(const DeviceState& state, HistoryStore& store, const OpBatch& batch, const AsOp& op, Transaction* txn,
             SubmissionCaptures* captures = nullptr);

// A command buffer the layer never saw allocated, or whose operations it could not record, was submitted:
// every structure that exists now gets an unknown history (undone with the submission, through txn).
void ApplyUnknownCommandBuffer(const DeviceState& state, HistoryStore& store, Transaction* txn);
// After an allocation failure left what the layer recorded or applied incomplete: every structure's history made
// unknown, not undoably (unknown is never wrong), counted in FailureCounters::structures_made_unknown. With the
// store's lock held. It allocates too (the live structures' list, new records): a second failure leaves what it
// reached unknown and the rest as it was (counted as one more allocation failure); never throws.
void MakeAllUnknownAfterFailure(const DeviceState& state, HistoryStore& store);

// A top-level build's references, found when its submission completed (family traces): each referenced structure
// gets the build that last executed on it as the store holds it now, to tell a later rebuild of another layout
// from it; they are ordered by handle (ReferencedStructures::Find). Takes the store's lock itself (the capture
// processing lock may be held).
void RememberReferencedBuilds(const HistoryStore& store, ReferencedStructures& references);

// Serialization sizes read back on the host (vkWriteAccelerationStructuresPropertiesKHR, or a query result
// fetched with vkGetQueryPoolResults) for the structure's current contents.
void RecordSerializationSize(HistoryStore& store, VkAccelerationStructureKHR as, uint64_t generation, uint64_t size);

// A device deserialization's captured bytes matched the content of the serialization it read (DeserializeCheck,
// judged when its submission completed): dst gets the serialized structure's history back (last build and
// activity), unless its record changed since the deserialization was applied (another operation on it, or a write
// over its memory). True when restored. Called with the store's lock held, outside any submission's transaction:
// the restore is not undone.
bool RestoreDeserializedHistory(HistoryStore& store, const DeserializeCheck& check);

// An update (op) paired with its source's activity as the history holds it now (the build that last executed on
// it), to be compared with the update's own activity `after` (pInfos-03663, 03664, 03768). Store's lock held.
ActivityComparison ComparisonWithSource(const HistoryStore& store, const AsOp& op,
                                        std::shared_ptr<BuildActivity> after);

// Where serialized bytes end: the header's total size (bytes 32..39, VK_UUID_SIZE * 2 in) of host data.
uint64_t SerializedHostSize(const void* data);

}  // namespace asval
