#include "common/process/image_conversion.h"

#include <cstring>
#include <stdexcept>
#include <string>

namespace vimot {

image_t to_lcm_image(const cv::Mat& grey, int64_t utime) {
  if (grey.type() != CV_8UC1 || grey.empty()) {
    throw std::invalid_argument("to_lcm_image: expected a non-empty 8-bit single-channel image");
  }
  image_t msg;
  msg.utime = utime;
  msg.width = grey.cols;
  msg.height = grey.rows;
  msg.row_stride = grey.cols;
  msg.pixelformat = image_t::PIXEL_FORMAT_GRAY;
  msg.size = grey.cols * grey.rows;
  msg.data.resize(static_cast<std::size_t>(msg.size));
  for (int r = 0; r < grey.rows; ++r) {
    std::memcpy(msg.data.data() + static_cast<std::size_t>(r) * grey.cols, grey.ptr<uint8_t>(r),
                static_cast<std::size_t>(grey.cols));
  }
  msg.nmetadata = 0;
  return msg;
}

cv::Mat grey_from_lcm_image(const image_t& msg) {
  const auto fail = [&](const std::string& what) {
    throw std::invalid_argument("image_t at utime " + std::to_string(msg.utime) + ": " + what);
  };
  if (msg.pixelformat != image_t::PIXEL_FORMAT_GRAY) {
    fail("pixel format " + std::to_string(msg.pixelformat) + " is not PIXEL_FORMAT_GRAY");
  }
  if (msg.width <= 0 || msg.height <= 0) fail("size " + std::to_string(msg.width) + "x" + std::to_string(msg.height));
  if (msg.row_stride < msg.width) fail("row_stride " + std::to_string(msg.row_stride) + " < width");
  if (static_cast<int64_t>(msg.size) != static_cast<int64_t>(msg.height) * msg.row_stride ||
      msg.data.size() != static_cast<std::size_t>(msg.size)) {
    fail("size " + std::to_string(msg.size) + " != height x row_stride");
  }
  // The message owns the bytes; the cv::Mat header over them is cloned.
  return cv::Mat(msg.height, msg.width, CV_8UC1, const_cast<uint8_t*>(msg.data.data()),
                 static_cast<std::size_t>(msg.row_stride))
      .clone();
}

mask_t to_lcm_mask(const cv::Mat& mask, int64_t utime, int camera_id) {
  if (mask.type() != CV_8UC1 || mask.empty()) {
    throw std::invalid_argument("to_lcm_mask: expected a non-empty 8-bit single-channel mask");
  }
  const cv::Mat packed = mask.isContinuous() ? mask : mask.clone();
  mask_t msg;
  msg.utime = utime;
  msg.camera_id = static_cast<int8_t>(camera_id);
  msg.width = packed.cols;
  msg.height = packed.rows;
  msg.data.assign(packed.datastart, packed.dataend);
  msg.size = static_cast<int32_t>(msg.data.size());
  return msg;
}

cv::Mat mask_from_lcm(const mask_t& msg) {
  if (msg.width <= 0 || msg.height <= 0 || static_cast<int64_t>(msg.width) * msg.height != msg.size ||
      msg.data.size() != static_cast<std::size_t>(msg.size)) {
    throw std::invalid_argument("mask_t at utime " + std::to_string(msg.utime) + ": " + std::to_string(msg.width) +
                                "x" + std::to_string(msg.height) + " with size " + std::to_string(msg.size) +
                                " and " + std::to_string(msg.data.size()) + " bytes");
  }
  return cv::Mat(msg.height, msg.width, CV_8UC1, const_cast<uint8_t*>(msg.data.data())).clone();
}

}  // namespace vimot
