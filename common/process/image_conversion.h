#pragma once
// vimot.image_t <-> cv::Mat, the one place images cross the LCM boundary.
// Kept apart from lcm_conversions.h so processes without images do not link
// OpenCV.

#include <opencv2/core.hpp>

#include "vimot/image_t.hpp"

namespace vimot {

/// An 8-bit grey image (a copy; row_stride padding removed). Throws
/// std::invalid_argument saying what is wrong for a pixel format other than
/// PIXEL_FORMAT_GRAY, a non-positive size, a row_stride below the width, or
/// fewer data bytes than the rows need.
cv::Mat image_from_lcm(const image_t& msg);

}  // namespace vimot
