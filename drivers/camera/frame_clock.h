#pragma once
// The utime of each frame of one camera.
//
// Host mode: utime = host time at capture − latency, where latency is the
// configured delay from exposure to the frame reaching the host (USB
// transfer, driver queue), so the stamp is the exposure time on the host
// clock. File-rate mode (video files): utime = start + round(i · 1e6 / fps)
// for the i-th frame (i = 0, 1, ...), the same on every run.
//
// Stamps never go backwards: a frame whose utime is not after the last one
// (a host clock step, a jittered read) is dropped and counted, so consumers
// that order by utime never see a repeat.

#include <cstdint>
#include <optional>

namespace vimot::camera {

enum class TimestampMode { kHost, kFileRate };

class FrameClock {
 public:
  /// kHost uses `latency_us`; kFileRate uses `start_utime` and `fps` (> 0).
  FrameClock(TimestampMode mode, int64_t latency_us, int64_t start_utime, double fps);

  /// The next frame's utime, or nullopt when it is not after the previous
  /// stamp given (the frame is dropped). `host_utime`: host time at capture.
  std::optional<int64_t> stamp(int64_t host_utime);

  int64_t non_increasing() const { return non_increasing_; }

 private:
  TimestampMode mode_;
  int64_t latency_us_;
  int64_t start_utime_;
  double fps_;
  int64_t index_{0};
  std::optional<int64_t> last_;
  int64_t non_increasing_{0};
};

}  // namespace vimot::camera
