#pragma once
// Pairs the frames of two free-running cameras by time: a left and a right
// frame whose stamps differ by at most `tolerance` make a stereo pair,
// published with the left stamp on both images (the feature tracker pairs
// by equal utime). Frames arrive in stamp order per camera; a frame that
// can no longer find a partner (the other camera's oldest frame is later
// by more than the tolerance), or that waits while the other camera
// delivers nothing, is dropped and counted as unpaired.

#include <cstdint>
#include <deque>
#include <opencv2/core.hpp>
#include <optional>

namespace vimot::camera {

struct StampedFrame {
  int64_t utime{0};
  cv::Mat image;
};

struct StereoPair {
  int64_t utime{0};  // the left frame's
  cv::Mat left;
  cv::Mat right;
};

class StereoPairer {
 public:
  /// `max_waiting`: frames one camera may queue while the other delivers
  /// none (a stalled device); older ones are dropped as unpaired.
  StereoPairer(int64_t tolerance_us, std::size_t max_waiting);

  /// camera 0 = left, 1 = right; stamps per camera strictly increasing.
  void add(int camera, StampedFrame frame);
  /// The next pair, if one is ready.
  std::optional<StereoPair> next();

  int64_t unpaired(int camera) const { return unpaired_[camera]; }

 private:
  int64_t tolerance_us_;
  std::size_t max_waiting_;
  std::deque<StampedFrame> queue_[2];
  int64_t unpaired_[2] = {0, 0};
};

}  // namespace vimot::camera
