#include "footprint_report.h"

#include <fmt/format.h>

#include "location.h"

namespace asval {

std::string FormatFootprint(const LayerFootprint& f) {
  const CaptureFootprint& c = f.capture;
  return fmt::format(
      "Layer footprint at vkDestroyDevice (what the layer holds for this device now; peak_*: the most it held at "
      "once): memories={} buffers={} structures={} address_ranges={} host_mappings={} command_buffers={} "
      "recorded_operations={} capture_logs={} capture_log_slabs={} capture_log_bytes={} history_records={} "
      "history_record_slots={} history_spans={} serialized_blobs={} query_slots={} spare_transactions={} "
      "query_pools={} deferred_operations={} build_size_entries={} capture_slabs={} capture_slabs_in_use={} "
      "capture_slab_bytes={} capture_pending_submissions={} capture_spare_fences={} peak_history_records={} "
      "peak_serialized_blobs={} peak_query_slots={} peak_capture_slabs_in_use={} peak_capture_pending_submissions={}",
      f.memories, f.buffers, f.structures, f.address_ranges, f.host_mappings, f.command_buffers,
      f.recorded_operations, f.capture_logs, f.capture_log_slabs, f.capture_log_bytes, f.history_records,
      f.history_record_slots, f.history_spans, f.serialized_blobs, f.query_slots, f.spare_transactions, f.query_pools,
      f.deferred_operations, f.build_size_entries, c.slabs, c.slabs_in_use, c.slab_bytes, c.pending_submissions,
      c.spare_fences, f.peak_history_records, f.peak_serialized_blobs, f.peak_query_slots, c.peak_slabs_in_use,
      c.peak_pending_submissions);
}

void ReportFootprint(const LayerFootprint& f, Reporter& reporter, VkDevice device) {
  reporter.Report(Severity::kInfo, kLayerFootprintId, Location("vkDestroyDevice"),
                  {Obj(VK_OBJECT_TYPE_DEVICE, device)}, FormatFootprint(f));
}

}  // namespace asval
