#include "reporter.h"

#include <spdlog/logger.h>
#include <spdlog/sinks/stdout_sinks.h>

#include <cinttypes>
#include <cstring>
#include <new>
#include <nlohmann/json.hpp>

#include "protect_scope.h"
#include "vk_enum_string.h"
#include "vuid_table.h"

namespace asval {

namespace {

constexpr const char* kSpecUrl = "https://docs.vulkan.org/spec/latest/chapters/accelstructures.html#";

std::string Hex(uint64_t v) {
  char buf[24];
  std::snprintf(buf, sizeof(buf), "0x%" PRIx64, v);
  return buf;
}

spdlog::level::level_enum LogLevel(Severity severity) {
  switch (severity) {
    case Severity::kError: return spdlog::level::err;
    case Severity::kWarning: return spdlog::level::warn;
    case Severity::kInfo: break;
  }
  return spdlog::level::info;
}

// One line of the report file. Keys keep their insertion order (ordered_json), so lines read as before.
// Object names come from the app and need not be UTF-8: replace turns invalid bytes into U+FFFD instead of
// writing a line no JSON parser accepts (or throwing); valid UTF-8 is written as is, not \u-escaped.
std::string JsonLine(const nlohmann::ordered_json& value) {
  return value.dump(-1, ' ', /*ensure_ascii=*/false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
}

}  // namespace

Reporter::Reporter(ReportSettings settings)
    : settings_(std::move(settings)), filter_(settings_.message_id_filter) {
  // A private logger (not in spdlog's global registry, which an app using spdlog may own).
  stderr_logger_ = std::make_shared<spdlog::logger>("asval", std::make_shared<spdlog::sinks::stderr_sink_mt>());
  stderr_logger_->set_pattern("asval: %v");
  stderr_logger_->set_level(spdlog::level::trace);
  if (!settings_.report_file.empty()) {
    // Appended to, so that several instances in one process (or a test run) share one report.
    json_file_ = std::fopen(settings_.report_file.c_str(), "a");
    if (!json_file_) {
      stderr_logger_->error("cannot open report_file '{}': {}", settings_.report_file, std::strerror(errno));
    }
  }
}

Reporter::~Reporter() {
  if (json_file_) std::fclose(json_file_);
}

void Reporter::AddMessenger(VkDebugUtilsMessengerEXT handle, const VkDebugUtilsMessengerCreateInfoEXT& info) {
  if (!info.pfnUserCallback) return;
  std::unique_lock lock(messengers_mutex_);
  messengers_.push_back(
      Messenger{handle, info.messageSeverity, info.messageType, info.pfnUserCallback, info.pUserData});
}

void Reporter::RemoveMessenger(VkDebugUtilsMessengerEXT handle) {
  std::unique_lock lock(messengers_mutex_);
  for (size_t i = messengers_.size(); i-- > 0;) {
    if (messengers_[i].handle == handle) messengers_.erase(messengers_.begin() + static_cast<ptrdiff_t>(i));
  }
}

bool Reporter::KeepsNameOf(VkObjectType type) {
  // The types asval's messages name (ReportObject), each of which the layer sees end.
  switch (type) {
    case VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR:  // vkDestroyAccelerationStructureKHR
    case VK_OBJECT_TYPE_COMMAND_BUFFER:              // vkFreeCommandBuffers, vkDestroyCommandPool
    case VK_OBJECT_TYPE_QUEUE:                       // vkDestroyDevice
    case VK_OBJECT_TYPE_DEVICE:
      return true;
    default:
      return false;
  }
}

void Reporter::SetObjectName(VkDevice device, VkObjectType type, uint64_t handle, const char* name) {
  if (!KeepsNameOf(type)) return;
  std::unique_lock lock(names_mutex_);
  if (!name || !*name) {
    names_.erase(NamedObject{type, handle});
  } else {
    names_[NamedObject{type, handle}] = ObjectNameEntry{device, name};
  }
  name_count_.store(names_.size(), std::memory_order_relaxed);
}

void Reporter::ForgetObjectName(ReportObject object) {
  // Relaxed: a name set on another thread for an object this thread destroys would break the app's own
  // synchronization of that object.
  if (name_count_.load(std::memory_order_relaxed) == 0) return;
  std::unique_lock lock(names_mutex_);
  names_.erase(NamedObject{object.type, object.handle});
  name_count_.store(names_.size(), std::memory_order_relaxed);
}

void Reporter::ForgetObjectNames(VkDevice device) {
  if (name_count_.load(std::memory_order_relaxed) == 0) return;
  std::unique_lock lock(names_mutex_);
  for (auto it = names_.begin(); it != names_.end();) {
    it = it->second.device == device ? names_.erase(it) : std::next(it);
  }
  name_count_.store(names_.size(), std::memory_order_relaxed);
}

std::string Reporter::ObjectName(VkObjectType type, uint64_t handle) const {
  if (name_count_.load(std::memory_order_relaxed) == 0) return std::string();
  std::shared_lock lock(names_mutex_);
  auto it = names_.find(NamedObject{type, handle});
  return it == names_.end() ? std::string() : it->second.name;
}

bool Reporter::SeverityEnabled(Severity s) const {
  switch (s) {
    case Severity::kError: return settings_.report_errors;
    case Severity::kWarning: return settings_.report_warnings;
    case Severity::kInfo: break;
  }
  return settings_.report_info;
}

bool Reporter::CountDuplicate(uint32_t hash, bool* last) {
  *last = false;
  if (settings_.duplicate_message_limit == 0) return true;
  std::lock_guard lock(duplicates_mutex_);
  uint32_t& count = duplicate_counts_[hash];
  if (count >= settings_.duplicate_message_limit) return false;
  ++count;
  *last = count == settings_.duplicate_message_limit;
  return true;
}

bool Reporter::Report(Severity severity, std::string_view vuid_in, const Location& loc,
                      std::initializer_list<ReportObject> objects, std::string_view message, NamedCounts counts) {
  bool skip = false;
  try {
    ReportOrThrow(severity, vuid_in, loc, objects, message, counts, &skip);
  } catch (const std::bad_alloc&) {
    // The message could not be built or written (the layer's allocation failed, or a callback's): lost, counted
    // (ASVAL-History-Summary says how many), never thrown into the app's Vulkan call. A callback that already
    // asked to skip the call still has its way.
    reports_lost_.fetch_add(1, std::memory_order_relaxed);
  }
  return skip;
}

void Reporter::ReportOrThrow(Severity severity, std::string_view vuid_in, const Location& loc,
                             std::initializer_list<ReportObject> objects, std::string_view message,
                             NamedCounts counts, bool* skip) {
  if (!SeverityEnabled(severity)) return;
  const std::string_view vuid = NewestVuid(vuid_in);
  const uint32_t hash = MessageIdHash(vuid);
  if (filter_.Mutes(vuid, hash)) return;
  if (settings_.protect && severity == Severity::kError) {
    *skip = true;  // before anything that may throw
    ProtectScope::NoteError(vuid, loc);
  }
  bool last = false;
  if (!CountDuplicate(hash, &last)) return;
  CounterFor(severity).fetch_add(1, std::memory_order_relaxed);
  Deliver(severity, vuid, hash, last, loc, objects, message, counts, skip);
}

void Reporter::ReportLayerAction(std::string_view id, const Location& loc, std::initializer_list<ReportObject> objects,
                                 std::string_view message) {
  try {
    const uint32_t hash = MessageIdHash(id);
    if (filter_.Mutes(id, hash)) return;
    CounterFor(Severity::kInfo).fetch_add(1, std::memory_order_relaxed);
    bool skip_ignored = false;
    Deliver(Severity::kInfo, id, hash, /*last=*/false, loc, objects, message, NamedCounts{}, &skip_ignored);
  } catch (const std::bad_alloc&) {
    reports_lost_.fetch_add(1, std::memory_order_relaxed);
  }
}

void Reporter::Deliver(Severity severity, std::string_view vuid, uint32_t hash, bool last, const Location& loc,
                       std::initializer_list<ReportObject> objects, std::string_view message, NamedCounts counts,
                       bool* skip_out) {
  bool& skip = *skip_out;
  const VuidInfo* info = FindVuid(vuid);
  const std::string_view spec_text = info ? std::string_view(info->spec_text) : std::string_view();
  const std::string path = loc.Path();

  // "Validation Error: [ VUID ] | MessageID = 0x... | vkFn(): path message" then spec text and objects.
  std::string text;
  text.reserve(256 + message.size() + spec_text.size());
  text.append(SeverityHeading(severity)).append(": [ ").append(vuid).append(" ] | MessageID = ");
  text.append(Hex(hash)).append("\n");
  if (last) {
    text.append("(Warning - This VUID has now been reported ")
        .append(std::to_string(settings_.duplicate_message_limit))
        .append(" times, which is the duplicate_message_limit value, this will be the last time reporting it).\n");
  }
  text.append(loc.Function()).append("(): ");
  if (!path.empty()) text.append(path).append(" ");
  text.append(message);
  if (!spec_text.empty()) {
    text.append("\nThe Vulkan spec states: ").append(spec_text).append(" (").append(kSpecUrl).append(vuid).append(")");
  }

  // Objects, with the names the app set through vkSetDebugUtilsObjectNameEXT; null handles are skipped.
  std::vector<std::string> names;
  std::vector<VkDebugUtilsObjectNameInfoEXT> object_infos;
  names.reserve(objects.size());
  object_infos.reserve(objects.size());
  for (const ReportObject& o : objects) {
    if (o.handle == 0) continue;
    names.push_back(ObjectName(o.type, o.handle));
  }
  size_t name_index = 0;
  for (const ReportObject& o : objects) {
    if (o.handle == 0) continue;
    const std::string& name = names[name_index++];
    object_infos.push_back(VkDebugUtilsObjectNameInfoEXT{VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT, nullptr,
                                                         o.type, o.handle, name.empty() ? nullptr : name.c_str()});
  }
  if (!object_infos.empty()) {
    text.append("\nObjects: ").append(std::to_string(object_infos.size()));
    for (size_t i = 0; i < object_infos.size(); ++i) {
      const VkDebugUtilsObjectNameInfoEXT& o = object_infos[i];
      text.append("\n    [").append(std::to_string(i)).append("] ").append(ObjectTypeName(o.objectType));
      text.append(" ").append(Hex(o.objectHandle));
      if (o.pObjectName) text.append("[").append(o.pObjectName).append("]");
    }
  }

  const std::string vuid_string(vuid);
  VkDebugUtilsMessengerCallbackDataEXT data{};
  data.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CALLBACK_DATA_EXT;
  data.pMessageIdName = vuid_string.c_str();
  data.messageIdNumber = static_cast<int32_t>(hash);
  data.pMessage = text.c_str();
  data.objectCount = static_cast<uint32_t>(object_infos.size());
  data.pObjects = object_infos.data();

  const VkDebugUtilsMessageSeverityFlagBitsEXT vk_severity = ToDebugUtilsSeverity(severity);
  bool delivered = false;
  {
    // Copy the list so that no lock is held while app code runs (a callback may call Vulkan).
    std::vector<Messenger> targets;
    {
      std::shared_lock lock(messengers_mutex_);
      targets = messengers_;
    }
    for (const Messenger& m : targets) {
      if (!(m.severities & vk_severity) || !(m.types & VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT)) continue;
      delivered = true;
      if (m.callback(vk_severity, VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT, &data, m.user_data) == VK_TRUE) {
        skip = true;
      }
    }
  }
  if (!delivered || settings_.log_to_stderr) {
    stderr_logger_->log(LogLevel(severity), text);
  }
  WriteJson(severity, vuid, hash, loc, objects, message, spec_text, counts);
}

std::atomic<uint64_t>& Reporter::CounterFor(Severity severity) {
  switch (severity) {
    case Severity::kError: return error_count_;
    case Severity::kWarning: return warning_count_;
    case Severity::kInfo: break;
  }
  return info_count_;
}

void Reporter::WriteJson(Severity severity, std::string_view vuid, uint32_t hash, const Location& loc,
                         std::initializer_list<ReportObject> objects, std::string_view message,
                         std::string_view spec_text, NamedCounts counts) {
  if (!json_file_) return;
  nlohmann::ordered_json json_objects = nlohmann::ordered_json::array();
  for (const ReportObject& o : objects) {
    if (o.handle == 0) continue;
    nlohmann::ordered_json object = {{"type", ObjectTypeName(o.type)}, {"handle", Hex(o.handle)}};
    const std::string name = ObjectName(o.type, o.handle);
    if (!name.empty()) object["name"] = name;
    json_objects.push_back(std::move(object));
  }
  nlohmann::ordered_json line = {
      {"severity", SeverityName(severity)},
      {"vuid", vuid},
      {"message_id", Hex(hash)},
      {"function", loc.Function()},
      {"location", loc.Path()},
      {"objects", std::move(json_objects)},
      {"message", message},
      {"spec_text", spec_text},
  };
  if (!counts.field.empty()) {
    nlohmann::ordered_json named = nlohmann::ordered_json::object();
    for (std::size_t i = 0; i < counts.size; ++i) named[std::string(counts.counts[i].name)] = counts.counts[i].count;
    line[std::string(counts.field)] = std::move(named);
  }
  WriteLine(JsonLine(line));
}

void Reporter::LayerNotice(Severity severity, std::string_view text) {
  stderr_logger_->log(LogLevel(severity), text);
  if (!json_file_) return;
  const nlohmann::ordered_json line = {
      {"severity", SeverityName(severity)}, {"vuid", "ASVAL-layer-notice"}, {"message", text}};
  WriteLine(JsonLine(line));
}

void Reporter::WriteLine(const std::string& line) {
  std::lock_guard lock(json_mutex_);
  std::fwrite(line.data(), 1, line.size(), json_file_);
  std::fflush(json_file_);  // a crash of the app must not lose what was already found
}

}  // namespace asval
