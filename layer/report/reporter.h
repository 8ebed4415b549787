#pragma once
// The reporter: one per VkInstance. It delivers findings to the app's VK_EXT_debug_utils messengers (calling
// them itself, as the Khronos layer does), else to stderr, and to the JSON-lines report; it applies the
// duplicate limit and the mute list. Everything here runs only when something is reported, never on the
// clean hot path.
#include <vulkan/vulkan.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <mutex>
#include <shared_mutex>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "location.h"
#include "message_id.h"
#include "severity.h"

namespace spdlog { class logger; }

namespace asval {

struct ReportSettings {
  bool report_errors = true;
  bool report_warnings = true;
  bool report_info = false;
  uint32_t duplicate_message_limit = 10;  // per VUID; 0 = unlimited
  std::vector<std::string> message_id_filter;
  std::string report_file;                // JSON lines; empty = none
  bool log_to_stderr = false;             // also print when the app has a messenger
  // Protect mode (protect_scope.h): every error that passes the severity filter and the mute list makes Report
  // return true, also past the duplicate limit, so that the call that broke a rule never reaches the driver.
  bool protect = false;
};

struct ReportObject {
  VkObjectType type;
  uint64_t handle;
};

// Counts a message carries in its JSON line as one object, {"name": count, ...}, under the key `field` (the
// summaries' counts, so that a tool reads them without parsing the text). Views of the caller's, used during Report.
struct NamedCount {
  std::string_view name;
  uint64_t count;
};
struct NamedCounts {
  std::string_view field;  // empty: none
  const NamedCount* counts = nullptr;
  std::size_t size = 0;
};

template <typename Handle>
ReportObject Obj(VkObjectType type, Handle handle) {
  return ReportObject{type, reinterpret_cast<uint64_t>(handle)};
}

class Reporter {
 public:
  explicit Reporter(ReportSettings settings);
  ~Reporter();
  Reporter(const Reporter&) = delete;
  Reporter& operator=(const Reporter&) = delete;

  // Messengers the app created with vkCreateDebugUtilsMessengerEXT (handle) or chained into
  // VkInstanceCreateInfo (handle VK_NULL_HANDLE; active only during vkCreateInstance/vkDestroyInstance, as the
  // spec says, so that an app passing the same create info both ways gets each message once).
  void AddMessenger(VkDebugUtilsMessengerEXT handle, const VkDebugUtilsMessengerCreateInfoEXT& info);
  void RemoveMessenger(VkDebugUtilsMessengerEXT handle);
  void RemoveCreateTimeMessengers() { RemoveMessenger(VK_NULL_HANDLE); }

  // Names the app set with vkSetDebugUtilsObjectNameEXT on `device`, shown with the objects asval's messages
  // name. Kept only for the types those messages name, each forgotten when its object ends (ForgetObjectName from
  // the destroy and free hooks, ForgetObjectNames at vkDestroyDevice), so that per-frame objects do not grow the
  // table and a new object given a dead one's handle value is never shown under the dead one's name. A null or empty
  // name forgets it too.
  void SetObjectName(VkDevice device, VkObjectType type, uint64_t handle, const char* name);
  void ForgetObjectName(ReportObject object);  // takes no lock while no name is kept
  void ForgetObjectNames(VkDevice device);
  static bool KeepsNameOf(VkObjectType type);

  // Reports one finding. vuid may be an older spelling: the newest is reported. Returns true when the call must
  // not be passed down: a messenger callback returned VK_TRUE (the app asks the layer to skip it), or, in protect
  // mode, the finding is an error (noted in the thread's ProtectScope, protect_scope.h).
  // `counts`: named counts for the JSON line (NamedCounts); the text says them itself.
  bool Report(Severity severity, std::string_view vuid, const Location& loc,
              std::initializer_list<ReportObject> objects, std::string_view message, NamedCounts counts = {});

  // Reports what the layer itself did to the app's call (protect mode withheld it): an information message that
  // report_flags and the duplicate limit do not hide, since each withheld call is named once and a CI run must see
  // why its app failed; the mute list still applies. Never asks to skip.
  void ReportLayerAction(std::string_view id, const Location& loc, std::initializer_list<ReportObject> objects,
                         std::string_view message);
  bool protects() const { return settings_.protect; }

  // Findings delivered so far (after filters and limits), by severity, for summaries and tests.
  uint64_t ErrorCount() const { return error_count_.load(std::memory_order_relaxed); }
  uint64_t WarningCount() const { return warning_count_.load(std::memory_order_relaxed); }
  uint64_t InfoCount() const { return info_count_.load(std::memory_order_relaxed); }
  // Messages that could not be built or written: an allocation failed (std::bad_alloc is caught, never thrown
  // into the app's call).
  uint64_t ReportsLost() const { return reports_lost_.load(std::memory_order_relaxed); }

  // A line for the layer's own problems (bad settings, internal failures): stderr and the report file.
  void LayerNotice(Severity severity, std::string_view text);

 private:
  struct Messenger {
    VkDebugUtilsMessengerEXT handle;
    VkDebugUtilsMessageSeverityFlagsEXT severities;
    VkDebugUtilsMessageTypeFlagsEXT types;
    PFN_vkDebugUtilsMessengerCallbackEXT callback;
    void* user_data;
  };

  // Report's body; *skip is set as soon as a callback asks to skip, so that it stands if a later step throws.
  void ReportOrThrow(Severity severity, std::string_view vuid, const Location& loc,
                     std::initializer_list<ReportObject> objects, std::string_view message, NamedCounts counts,
                     bool* skip);
  // Builds the text and delivers it (messengers, stderr, JSON): what is left of a report after the filters.
  // `last`: this is the last message the duplicate limit lets through for its id.
  void Deliver(Severity severity, std::string_view vuid, uint32_t hash, bool last, const Location& loc,
               std::initializer_list<ReportObject> objects, std::string_view message, NamedCounts counts,
               bool* skip);
  bool SeverityEnabled(Severity s) const;
  // Returns false when the duplicate limit drops the message; sets *last when this is the last one allowed.
  bool CountDuplicate(uint32_t hash, bool* last);
  std::string ObjectName(VkObjectType type, uint64_t handle) const;
  std::atomic<uint64_t>& CounterFor(Severity severity);
  void WriteJson(Severity severity, std::string_view vuid, uint32_t hash, const Location& loc,
                 std::initializer_list<ReportObject> objects, std::string_view message, std::string_view spec_text,
                 NamedCounts counts);
  void WriteLine(const std::string& line);  // one JSON line to the report file, flushed

  const ReportSettings settings_;
  const MessageFilter filter_;

  mutable std::shared_mutex messengers_mutex_;
  std::vector<Messenger> messengers_;

  struct NamedObject {
    VkObjectType type;
    uint64_t handle;  // handles of different types may share a value
    bool operator==(const NamedObject& o) const { return type == o.type && handle == o.handle; }
  };
  struct NamedObjectHash {
    std::size_t operator()(const NamedObject& o) const {
      return std::hash<uint64_t>{}(o.handle * 0x9e3779b97f4a7c15ull + static_cast<uint64_t>(o.type));
    }
  };
  struct ObjectNameEntry {
    VkDevice device;  // the object's device: its names end with it
    std::string name;
  };
  mutable std::shared_mutex names_mutex_;
  std::unordered_map<NamedObject, ObjectNameEntry, NamedObjectHash> names_;
  std::atomic<std::size_t> name_count_{0};  // names_.size(), read without the lock

  std::mutex duplicates_mutex_;
  std::unordered_map<uint32_t, uint32_t> duplicate_counts_;

  std::mutex json_mutex_;
  std::FILE* json_file_ = nullptr;

  std::shared_ptr<spdlog::logger> stderr_logger_;
  std::atomic<uint64_t> reports_lost_{0};
  std::atomic<uint64_t> error_count_{0};
  std::atomic<uint64_t> warning_count_{0};
  std::atomic<uint64_t> info_count_{0};
};

}  // namespace asval
