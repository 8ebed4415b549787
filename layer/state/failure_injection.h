#pragma once
// Test hook (issue 14, failure paths): failures injected into the layer's own allocations and its own Vulkan
// calls, so that tests can show each one ends in "skipped and counted" (FailureCounters, ASVAL-History-Summary)
// while the app's call goes through with its own result.
//
//   ASVAL_TEST_FAIL="<point>:<nth>[:<count>],..."
//
// read when a device is created (DeviceState's constructor; every device creation reads it again and starts the
// counts afresh, so tests create one device at a time while it is set). The nth time (1-based) the layer reaches
// a site of `point`, and the count - 1 times after it (count: 1 when not given), fail. Each entry counts on its
// own. Points (a site belongs to every point that names it):
//   state_alloc        every state_* point and capture_alloc: the layer's own allocation throws std::bad_alloc
//                      there, as a real failure does
//   state_object       a shadow record: memory, buffer (its creation or binding), structure, command pool or
//                      buffer, query pool, mapping
//   state_structure    a structure's shadow record only
//   state_record       an operation appended to a command buffer's recording (a device command), or the recording
//                      published at vkEndCommandBuffer
//   state_host         a host command's operations (built once for its checks, once more for its history)
//   state_apply        an operation applied to the histories (at submission; a host command's when it completes)
//   capture_alloc      the capture's bookkeeping while it records a build or serialization command's copies (its
//                      log, its lists): the command's captures are dropped before any is recorded
//   capture_memory     a capture slab: the layer's vkAllocateMemory answers VK_ERROR_OUT_OF_DEVICE_MEMORY
//   inserted_commands  inserted_fence and inserted_pipeline
//   inserted_fence     the layer's vkCreateFence (the fence passed down with a capturing submission that has none)
//   inserted_pipeline  the layer's vkCreateComputePipelines (the reducing dispatch, capture_method reduce)
//
// Why an environment variable: the integration tests run the real loader in their own process and need no API to
// arm it; no app should find it among the settings (it is not one). Unset, it costs one relaxed atomic load per
// site reached.
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <new>
#include <string>
#include <string_view>
#include <vector>

namespace asval {

enum class FailSite : uint32_t {
  kObjectRecord,     // shadow records of memory, buffers, pools, command buffers, query pools, mappings
  kStructureRecord,  // a structure's shadow record
  kRecording,        // a device command's operations appended to its recording; vkEndCommandBuffer's snapshot
  kHostOps,          // a host command's operations
  kApply,            // one operation applied to the histories
  kCaptureRecord,    // the capture's own bookkeeping while it records a command's copies
  kCaptureMemory,    // a capture slab's memory
  kLayerFence,       // the layer's own fence
  kReducePipeline,   // the layer's reducing pipeline
};

constexpr uint32_t FailSiteBit(FailSite site) { return 1u << static_cast<uint32_t>(site); }

struct FailPointName {
  const char* name;
  uint32_t sites;
};

inline constexpr uint32_t kStateSites = FailSiteBit(FailSite::kObjectRecord) |
                                        FailSiteBit(FailSite::kStructureRecord) |
                                        FailSiteBit(FailSite::kRecording) | FailSiteBit(FailSite::kHostOps) |
                                        FailSiteBit(FailSite::kApply) | FailSiteBit(FailSite::kCaptureRecord);
inline constexpr uint32_t kInsertedSites = FailSiteBit(FailSite::kLayerFence) | FailSiteBit(FailSite::kReducePipeline);
inline constexpr FailPointName kFailPoints[] = {
    {"state_alloc", kStateSites},
    {"state_object", FailSiteBit(FailSite::kObjectRecord) | FailSiteBit(FailSite::kStructureRecord)},
    {"state_structure", FailSiteBit(FailSite::kStructureRecord)},
    {"state_record", FailSiteBit(FailSite::kRecording)},
    {"state_host", FailSiteBit(FailSite::kHostOps)},
    {"state_apply", FailSiteBit(FailSite::kApply)},
    {"capture_alloc", FailSiteBit(FailSite::kCaptureRecord)},
    {"capture_memory", FailSiteBit(FailSite::kCaptureMemory)},
    {"inserted_commands", kInsertedSites},
    {"inserted_fence", FailSiteBit(FailSite::kLayerFence)},
    {"inserted_pipeline", FailSiteBit(FailSite::kReducePipeline)},
};

// One entry of ASVAL_TEST_FAIL: the sites it counts, and which of their hits fail ([nth, nth + count)).
struct FailSpec {
  uint32_t sites = 0;
  uint64_t nth = 0;
  uint64_t count = 1;
};

namespace failure_detail {

// A decimal number >= 1 that fills `text`.
inline bool ParsePositive(std::string_view text, uint64_t* out) {
  if (text.empty() || text.size() > 18) return false;
  uint64_t value = 0;
  for (char c : text) {
    if (c < '0' || c > '9') return false;
    value = value * 10 + static_cast<uint64_t>(c - '0');
  }
  if (value == 0) return false;
  *out = value;
  return true;
}

}  // namespace failure_detail

// Pure: the entries of ASVAL_TEST_FAIL's text. False (with the reason in *error, and *out left empty) when any
// entry is malformed: the whole variable is then ignored, never half applied. An empty text is no entry.
inline bool ParseFailSpecs(std::string_view text, std::vector<FailSpec>* out, std::string* error) {
  out->clear();
  std::vector<FailSpec> specs;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = text.find(',', start);
    const std::string_view entry = text.substr(start, comma == std::string_view::npos ? std::string_view::npos
                                                                                      : comma - start);
    start = comma == std::string_view::npos ? text.size() + 1 : comma + 1;
    if (entry.empty()) {
      if (text.empty()) break;
      *error = "an empty entry";
      return false;
    }
    const std::size_t first = entry.find(':');
    if (first == std::string_view::npos) {
      *error = "'" + std::string(entry) + "' has no ':<nth>'";
      return false;
    }
    const std::string_view point = entry.substr(0, first);
    const std::string_view rest = entry.substr(first + 1);
    const std::size_t second = rest.find(':');
    FailSpec spec;
    for (const FailPointName& p : kFailPoints) {
      if (point == p.name) spec.sites = p.sites;
    }
    if (spec.sites == 0) {
      *error = "unknown point '" + std::string(point) + "'";
      return false;
    }
    if (!failure_detail::ParsePositive(rest.substr(0, second), &spec.nth) ||
        (second != std::string_view::npos && !failure_detail::ParsePositive(rest.substr(second + 1), &spec.count))) {
      *error = "'" + std::string(entry) + "': nth and count are whole numbers from 1";
      return false;
    }
    specs.push_back(spec);
  }
  *out = std::move(specs);
  return true;
}

class FailureInjector {
 public:
  static constexpr std::size_t kMaxSpecs = 8;

  // Replaces the entries and starts their counts afresh (an empty list disarms).
  void Arm(const std::vector<FailSpec>& specs) {
    std::lock_guard<std::mutex> lock(mutex_);
    count_ = 0;
    for (const FailSpec& s : specs) {
      if (count_ == kMaxSpecs) break;
      specs_[count_] = s;
      seen_[count_] = 0;
      ++count_;
    }
    armed_.store(count_ != 0, std::memory_order_relaxed);
  }
  bool armed() const { return armed_.load(std::memory_order_relaxed); }
  // The slow path of InjectedFailure: counts this hit of `site` for every entry that names it.
  bool Hit(FailSite site) {
    std::lock_guard<std::mutex> lock(mutex_);
    bool fail = false;
    for (std::size_t i = 0; i < count_; ++i) {
      if (!(specs_[i].sites & FailSiteBit(site))) continue;
      const uint64_t n = ++seen_[i];
      fail |= n >= specs_[i].nth && n - specs_[i].nth < specs_[i].count;
    }
    return fail;
  }

 private:
  std::atomic<bool> armed_{false};
  std::mutex mutex_;
  FailSpec specs_[kMaxSpecs] = {};
  uint64_t seen_[kMaxSpecs] = {};
  std::size_t count_ = 0;
};

// One per process (constant-initialized: no guard on the hot path).
inline FailureInjector g_failure_injector;

// Whether this hit of `site` is to fail. Unarmed: one relaxed load.
inline bool InjectedFailure(FailSite site) { return g_failure_injector.armed() && g_failure_injector.Hit(site); }
// The layer's allocation at `site` fails as a real one does.
inline void InjectBadAlloc(FailSite site) {
  if (InjectedFailure(site)) throw std::bad_alloc();
}

// Device creation: ASVAL_TEST_FAIL read again (unset or malformed: disarmed; malformed said on stderr).
inline void ArmFailureInjectionFromEnvironment() {
  const char* text = std::getenv("ASVAL_TEST_FAIL");
  std::vector<FailSpec> specs;
  std::string error;
  if (text && !ParseFailSpecs(text, &specs, &error)) {
    std::fprintf(stderr, "asval: ASVAL_TEST_FAIL ignored: %s\n", error.c_str());
  }
  g_failure_injector.Arm(specs);
}

}  // namespace asval
