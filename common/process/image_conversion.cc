#include "common/process/image_conversion.h"

#include <stdexcept>
#include <string>

namespace vimot {

cv::Mat image_from_lcm(const image_t& msg) {
  const std::string what = "image_t at utime " + std::to_string(msg.utime) + ": ";
  if (msg.pixelformat != image_t::PIXEL_FORMAT_GRAY) {
    throw std::invalid_argument(what + "pixel format " + std::to_string(msg.pixelformat) +
                                " is not supported (only PIXEL_FORMAT_GRAY, 8-bit grey)");
  }
  if (msg.width <= 0 || msg.height <= 0) {
    throw std::invalid_argument(what + "size " + std::to_string(msg.width) + "x" + std::to_string(msg.height) +
                                " must be positive");
  }
  if (msg.row_stride < msg.width) {
    throw std::invalid_argument(what + "row_stride " + std::to_string(msg.row_stride) + " is below the width " +
                                std::to_string(msg.width));
  }
  const int64_t needed = static_cast<int64_t>(msg.row_stride) * (msg.height - 1) + msg.width;
  if (static_cast<int64_t>(msg.data.size()) < needed || msg.size != static_cast<int32_t>(msg.data.size())) {
    throw std::invalid_argument(what + std::to_string(msg.data.size()) + " data bytes (size field " +
                                std::to_string(msg.size) + "), a " + std::to_string(msg.width) + "x" +
                                std::to_string(msg.height) + " image with row_stride " +
                                std::to_string(msg.row_stride) + " needs " + std::to_string(needed));
  }
  const cv::Mat view(msg.height, msg.width, CV_8UC1, const_cast<uint8_t*>(msg.data.data()),
                     static_cast<std::size_t>(msg.row_stride));
  return view.clone();
}

}  // namespace vimot
