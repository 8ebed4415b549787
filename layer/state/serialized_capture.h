#pragma once
// History through device-memory serialization (issue 12): when a submission whose serializations or
// deserializations of device bytes were captured completes, each serialization's content (the size its header
// gives and the hash of that many bytes) is filled, then each deserialization's captured bytes are compared with
// the content of the serialization the layer saw at that place, and on a match the destination's history is
// restored (history_apply.h RestoreDeserializedHistory). Never a guess: bytes not captured in full, a header that
// does not fit, a different hash or a destination changed since leave the history unknown (counted).
//
// Locking: called under the device's capture processing lock (CaptureTracker::Process, the only caller, through
// the loader's ProcessCaptures); takes the history store's lock itself, briefly, for each restore. The order is
// processing lock -> store lock, never the reverse: a submission applies its operations under the submission
// order lock and the store's lock, releases the store's lock (HistorySubmission::EndApply), and only then takes the
// processing lock (CaptureTracker::Reserve / Track), and no path holds the store's lock while taking the processing
// lock. The submission order lock is not taken here: a submitting thread holds it while waiting for the processing
// lock (Reserve), so taking it under the processing lock could deadlock. A restore may therefore land while another
// thread's submission is between its apply and its downcall; RestoreDeserializedHistory restores only the very
// record the deserialization left (same generation, not clobbered), which such a submission cannot have changed
// without this restore being declined, so an undo of it never meets a restored record it did not see.
#include "build_activity.h"
#include "capture_log.h"

namespace asval {

class HistoryStore;

// Reads the captured blob bytes: true with the header's serialized size and the hash of exactly that many bytes
// when they were all captured and can be read (not written twice before being read).
bool CapturedBlobContent(const CaptureLog& log, uint32_t blob, uint64_t* size, uint64_t* hash);

// The serializations and deserializations of one completed submission, in that order.
void CompleteSerializedCaptures(HistoryStore& store, CaptureCounters& counters, SubmissionCaptures& done);

}  // namespace asval
