#include "drivers/camera/stereo_pairer.h"

#include <cstdlib>
#include <stdexcept>
#include <string>

namespace vimot::camera {

StereoPairer::StereoPairer(int64_t tolerance_us, std::size_t max_waiting)
    : tolerance_us_(tolerance_us), max_waiting_(max_waiting) {
  if (tolerance_us_ < 0) throw std::invalid_argument("StereoPairer: tolerance must be >= 0 µs");
  if (max_waiting_ < 1) throw std::invalid_argument("StereoPairer: max_waiting must be >= 1");
}

void StereoPairer::add(int camera, StampedFrame frame) {
  if (camera != 0 && camera != 1) throw std::invalid_argument("StereoPairer: camera " + std::to_string(camera));
  std::deque<StampedFrame>& queue = queue_[camera];
  if (!queue.empty() && frame.utime <= queue.back().utime) {
    throw std::invalid_argument("StereoPairer: camera " + std::to_string(camera) + " stamp " +
                                std::to_string(frame.utime) + " not after " + std::to_string(queue.back().utime));
  }
  queue.push_back(std::move(frame));
  if (queue.size() > max_waiting_) {
    queue.pop_front();
    ++unpaired_[camera];
  }
}

std::optional<StereoPair> StereoPairer::next() {
  while (!queue_[0].empty() && !queue_[1].empty()) {
    const int64_t left = queue_[0].front().utime;
    const int64_t right = queue_[1].front().utime;
    if (std::abs(left - right) <= tolerance_us_) {
      StereoPair pair{left, std::move(queue_[0].front().image), std::move(queue_[1].front().image)};
      queue_[0].pop_front();
      queue_[1].pop_front();
      return pair;
    }
    // The older frame's partner would have been earlier than the other
    // camera's oldest frame: it will never come.
    const int older = left < right ? 0 : 1;
    queue_[older].pop_front();
    ++unpaired_[older];
  }
  return std::nullopt;
}

}  // namespace vimot::camera
