#pragma once
// Checkpoints of a long run (--checkpoints, bench/longrun): after the frames named, one line on stdout with the
// process's resident memory now and at its peak (/proc/self/status VmRSS, VmHWM), the bytes its heap has in use
// (glibc's mallinfo2: exact to the byte where resident memory moves by pages), and the wall and CPU time per
// frame of the frames just before (at most `kWindow`, never frame 1, which builds everything), so that one
// process shows whether memory and the frame cost stay flat over thousands of frames. CPU time (the process's,
// lavapipe's threads included) says more than wall time on a machine shared with other work.
#include <array>
#include <chrono>
#include <cstdint>
#include <vector>

namespace scene {

class FrameCheckpoints {
 public:
  static constexpr uint32_t kWindow = 100;

  // `at`: frame counts (1-based, ascending) after which a line is printed.
  explicit FrameCheckpoints(std::vector<uint32_t> at);
  // Before the first frame.
  void Start();
  // After each frame, with the number of frames done so far (Scene::after_frame).
  void AfterFrame(uint32_t frames_done);

 private:
  void Print(uint32_t frames_done) const;

  std::vector<uint32_t> at_;
  std::size_t next_ = 0;  // the next checkpoint in at_
  std::chrono::steady_clock::time_point last_;
  double last_cpu_ms_ = 0;
  // The last kWindow frame times (ms), frame 1 excluded, as a ring; filled_ of them valid.
  std::array<double, kWindow> ms_{};
  std::array<double, kWindow> cpu_ms_{};  // the same frames' process CPU time
  uint32_t filled_ = 0;
  uint32_t head_ = 0;
};

}  // namespace scene
