#pragma once
// cv::Mat <-> vimot.image_t for 8-bit grey images (PIXEL_FORMAT_GRAY), the
// one conversion image sources (EuRoC player, renderer, cameras) and image
// consumers (feature tracker) share.

#include <cstdint>

#include <opencv2/core.hpp>

#include "vimot/image_t.hpp"

namespace vimot {

/// A CV_8UC1 image as image_t, rows packed (row_stride = width), no
/// metadata. Throws std::invalid_argument for any other image type.
image_t to_lcm_image(const cv::Mat& grey, int64_t utime);

/// The pixels of a PIXEL_FORMAT_GRAY image_t as a CV_8UC1 (a copy). Throws
/// std::invalid_argument naming the problem for another pixel format, a
/// non-positive size, row_stride < width, or size != height · row_stride.
cv::Mat grey_from_lcm_image(const image_t& msg);

}  // namespace vimot
