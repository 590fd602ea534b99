#include "drivers/camera/frame_clock.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace vimot::camera {

FrameClock::FrameClock(TimestampMode mode, int64_t latency_us, int64_t start_utime, double fps)
    : mode_(mode), latency_us_(latency_us), start_utime_(start_utime), fps_(fps) {
  if (mode_ == TimestampMode::kFileRate && !(std::isfinite(fps_) && fps_ > 0.0)) {
    throw std::invalid_argument("FrameClock: file-rate stamps need fps > 0, got " + std::to_string(fps_));
  }
}

std::optional<int64_t> FrameClock::stamp(int64_t host_utime) {
  const int64_t utime = mode_ == TimestampMode::kHost
                            ? host_utime - latency_us_
                            // From the index, not by adding periods, so rounding never accumulates.
                            : start_utime_ + std::llround(static_cast<double>(index_) * 1e6 / fps_);
  ++index_;
  if (last_ && utime <= *last_) {
    ++non_increasing_;
    return std::nullopt;
  }
  last_ = utime;
  return utime;
}

}  // namespace vimot::camera
