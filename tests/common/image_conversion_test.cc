// cv::Mat <-> image_t (grey): round trip, padded rows, and every malformed
// message rejected with a reason instead of reading out of bounds.
#include <catch2/catch.hpp>

#include "common/process/image_conversion.h"

using Catch::Matchers::Contains;
using vimot::image_t;

namespace {

cv::Mat ramp(int rows, int cols) {
  cv::Mat m(rows, cols, CV_8UC1);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) m.at<uint8_t>(r, c) = static_cast<uint8_t>(7 * r + c);
  }
  return m;
}

}  // namespace

TEST_CASE("a grey image survives the round trip, row by row", "[image]") {
  const cv::Mat image = ramp(5, 7);
  const image_t msg = vimot::to_lcm_image(image, 42);
  CHECK(msg.utime == 42);
  CHECK(msg.width == 7);
  CHECK(msg.height == 5);
  CHECK(msg.row_stride == 7);
  CHECK(msg.size == 35);
  CHECK(msg.pixelformat == image_t::PIXEL_FORMAT_GRAY);
  CHECK(msg.nmetadata == 0);
  CHECK(msg.data[2 * 7 + 3] == 7 * 2 + 3);
  CHECK(cv::norm(vimot::grey_from_lcm_image(msg), image, cv::NORM_INF) == 0.0);
  // A view into a larger image (rows not contiguous) is packed.
  const cv::Mat big = ramp(10, 20);
  const image_t roi = vimot::to_lcm_image(big(cv::Rect(3, 2, 7, 5)), 0);
  CHECK(roi.row_stride == 7);
  CHECK(roi.data[0] == big.at<uint8_t>(2, 3));
  CHECK(roi.data[7] == big.at<uint8_t>(3, 3));
}

TEST_CASE("padded rows are read at their stride", "[image]") {
  image_t msg = vimot::to_lcm_image(ramp(3, 4), 0);
  msg.row_stride = 6;
  msg.size = 18;
  msg.data.assign(18, 0);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) msg.data[static_cast<std::size_t>(6 * r + c)] = static_cast<uint8_t>(7 * r + c);
  }
  CHECK(cv::norm(vimot::grey_from_lcm_image(msg), ramp(3, 4), cv::NORM_INF) == 0.0);
}

TEST_CASE("malformed image_t messages are rejected with a reason", "[image]") {
  const image_t good = vimot::to_lcm_image(ramp(3, 4), 9);
  image_t m = good;
  m.pixelformat = image_t::PIXEL_FORMAT_RGB;
  CHECK_THROWS_WITH(vimot::grey_from_lcm_image(m), Contains("PIXEL_FORMAT_GRAY"));
  m = good;
  m.width = 0;
  CHECK_THROWS_WITH(vimot::grey_from_lcm_image(m), Contains("size 0x3"));
  m = good;
  m.row_stride = 3;
  CHECK_THROWS_WITH(vimot::grey_from_lcm_image(m), Contains("row_stride 3 < width"));
  m = good;
  m.height = 4;  // 16 bytes promised, 12 carried
  CHECK_THROWS_WITH(vimot::grey_from_lcm_image(m), Contains("height x row_stride"));
  CHECK_THROWS_AS(vimot::to_lcm_image(cv::Mat(2, 2, CV_8UC3), 0), std::invalid_argument);
  CHECK_THROWS_AS(vimot::to_lcm_image(cv::Mat(), 0), std::invalid_argument);
}

TEST_CASE("a mask round-trips through mask_t; a malformed one is rejected", "[image]") {
  const cv::Mat mask = ramp(3, 4);
  const vimot::mask_t msg = vimot::to_lcm_mask(mask(cv::Rect(1, 0, 3, 3)), 5, 1);  // a non-continuous view
  CHECK(msg.utime == 5);
  CHECK(msg.camera_id == 1);
  CHECK(msg.size == 9);
  CHECK(cv::norm(vimot::mask_from_lcm(msg), mask(cv::Rect(1, 0, 3, 3)), cv::NORM_INF) == 0.0);
  vimot::mask_t m = msg;
  m.height = 4;  // 12 bytes promised, 9 carried
  CHECK_THROWS_WITH(vimot::mask_from_lcm(m), Contains("3x4 with size 9"));
  m = msg;
  m.data.pop_back();
  CHECK_THROWS_WITH(vimot::mask_from_lcm(m), Contains("8 bytes"));
  CHECK_THROWS_AS(vimot::to_lcm_mask(cv::Mat(2, 2, CV_8UC3), 0, 0), std::invalid_argument);
}
