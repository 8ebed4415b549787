#include "protect_marks.h"

#include <memory>
#include <new>

#include "device_state.h"

namespace asval {

namespace {

// What marks a command buffer when the named record cannot be made: the submission is withheld all the same.
std::shared_ptr<const WithheldCommand> UnnamedCommand() {
  static const WithheldCommand unnamed{"(a command)", "", "(not kept: the layer's allocation failed)"};
  return std::shared_ptr<const WithheldCommand>(std::shared_ptr<const WithheldCommand>(), &unnamed);
}

// The record of a withheld command; the unnamed one when it cannot be made.
std::shared_ptr<const WithheldCommand> MakeWithheld(DeviceState& state, std::string_view function,
                                                    std::string_view vuid, std::string_view where) {
  try {
    return std::make_shared<const WithheldCommand>(
        WithheldCommand{std::string(function), std::string(vuid), std::string(where)});
  } catch (const std::bad_alloc&) {
    state.failures().allocation_failures.fetch_add(1, std::memory_order_relaxed);
    return UnnamedCommand();
  }
}

}  // namespace

bool RecordWithheldCommand(DeviceState& state, VkCommandBuffer cb, std::string_view function, std::string_view vuid,
                           std::string_view where) {
  state.protect_counters.commands_withheld.fetch_add(1, std::memory_order_relaxed);
  return state.command_buffers.MarkWithheld(cb, MakeWithheld(state, function, vuid, where));
}

void RecordSubmissionHalt(DeviceState& state, std::string_view function, std::string_view vuid,
                          std::string_view where) {
  state.protect_halt.Set(MakeWithheld(state, function, vuid, where));
}

void RecordWithheldSubmission(DeviceState& state) {
  state.protect_counters.submissions_withheld.fetch_add(1, std::memory_order_relaxed);
}

void RecordWithheldHostCommand(DeviceState& state) {
  state.protect_counters.host_commands_withheld.fetch_add(1, std::memory_order_relaxed);
}

void RecordSynchronizationLost(DeviceState& state) {
  state.failures().allocation_failures.fetch_add(1, std::memory_order_relaxed);
  state.protect_counters.synchronizations_lost.fetch_add(1, std::memory_order_relaxed);
}

}  // namespace asval
