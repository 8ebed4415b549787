#include "frame_checkpoints.h"

#include <malloc.h>
#include <time.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <utility>

namespace scene {

namespace {

// A "Name:   1234 kB" line of /proc/self/status, in kB; -1 where there is none (not Linux).
long StatusKb(const char* name) {
  std::FILE* f = std::fopen("/proc/self/status", "r");
  if (!f) return -1;
  char line[256];
  long kb = -1;
  const std::size_t n = std::strlen(name);
  while (std::fgets(line, sizeof(line), f)) {
    if (std::strncmp(line, name, n) == 0 && line[n] == ':') {
      kb = std::strtol(line + n + 1, nullptr, 10);
      break;
    }
  }
  std::fclose(f);
  return kb;
}

// The process's CPU time (every thread's), in ms.
double ProcessCpuMs() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

// Bytes the heap has handed out and not had back (small blocks and mmapped ones).
unsigned long long HeapInUse() {
  const struct mallinfo2 info = mallinfo2();
  return static_cast<unsigned long long>(info.uordblks) + static_cast<unsigned long long>(info.hblkhd);
}

}  // namespace

FrameCheckpoints::FrameCheckpoints(std::vector<uint32_t> at) : at_(std::move(at)) {}

void FrameCheckpoints::Start() {
  last_ = std::chrono::steady_clock::now();
  last_cpu_ms_ = ProcessCpuMs();
}

void FrameCheckpoints::AfterFrame(uint32_t frames_done) {
  const std::chrono::steady_clock::time_point now = std::chrono::steady_clock::now();
  const double cpu_ms = ProcessCpuMs();
  if (frames_done > 1) {
    ms_[head_] = std::chrono::duration<double, std::milli>(now - last_).count();
    cpu_ms_[head_] = cpu_ms - last_cpu_ms_;
    head_ = (head_ + 1) % kWindow;
    filled_ = std::min(filled_ + 1, kWindow);
  }
  if (next_ < at_.size() && frames_done == at_[next_]) {
    Print(frames_done);
    ++next_;
  }
  last_ = std::chrono::steady_clock::now();  // the printing is not the next frame's time
  last_cpu_ms_ = ProcessCpuMs();
}

void FrameCheckpoints::Print(uint32_t frames_done) const {
  std::array<double, kWindow> sorted = ms_;
  std::sort(sorted.begin(), sorted.begin() + filled_);
  double sum = 0, cpu_sum = 0;
  for (uint32_t k = 0; k < filled_; ++k) {
    sum += sorted[k];
    cpu_sum += cpu_ms_[k];
  }
  const double mean = filled_ ? sum / filled_ : 0.0;
  const double median = filled_ ? (filled_ % 2 ? sorted[filled_ / 2]
                                               : 0.5 * (sorted[filled_ / 2 - 1] + sorted[filled_ / 2]))
                                : 0.0;
  const double max = filled_ ? sorted[filled_ - 1] : 0.0;
  const double cpu_mean = filled_ ? cpu_sum / filled_ : 0.0;
  std::printf("checkpoint: frames %u; rss_kb %ld; rss_peak_kb %ld; heap_bytes %llu; frames %u..%u: mean %.3f ms, "
              "median %.3f ms, max %.3f ms, cpu %.3f ms\n",
              frames_done, StatusKb("VmRSS"), StatusKb("VmHWM"), HeapInUse(), frames_done - filled_ + 1, frames_done,
              mean, median, max, cpu_mean);
  std::fflush(stdout);
}

}  // namespace scene
