#pragma once
// Family traces, at submission (issue 29): the top-level structures the traces and ray queries of a submission read
// through bound descriptors, with what the build they read referenced, kept with the submission's in-flight batches
// (InFlightBatch::traced_tops). A bottom level destroyed, or its memory freed, while such a trace is pending is then
// found at the destroy (layer/checks/lifetime.h): the device traverses it.
//
// Only what is certain is kept: a top level whose latest write, in execution order after this submission, is a
// build that completed in an earlier submission (its references known) and that no command of this submission
// writes (the trace read that build). A submission with a batch deferred or of unknown order keeps nothing. Sets,
// pushed descriptors and descriptor-buffer bytes (read at submission) are followed. What is not kept is not judged
// (a destroy is then silent).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "device_state.h"
#include "in_flight.h"

namespace asval {

// staged[first..]: the batches of the submission `submission` (SubmissionCaptures::id), its operations applied to
// the history. Takes the history store's lock. Throws std::bad_alloc.
void NoteTracedTops(const DeviceState& state, uint64_t submission, std::vector<InFlightBatch>& staged,
                    std::size_t first);

}  // namespace asval
