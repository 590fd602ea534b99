#pragma once
// cv::Mat <-> vimot.image_t for 8-bit grey images (PIXEL_FORMAT_GRAY) and
// <-> vimot.mask_t for target masks, the
// one conversion image sources (EuRoC player, renderer, cameras) and image
// consumers (feature tracker) share.

#include <cstdint>

#include <opencv2/core.hpp>

#include "vimot/image_t.hpp"
#include "vimot/mask_t.hpp"

namespace vimot {

/// A CV_8UC1 image as image_t, rows packed (row_stride = width), no
/// metadata. Throws std::invalid_argument for any other image type.
image_t to_lcm_image(const cv::Mat& grey, int64_t utime);

/// The pixels of a PIXEL_FORMAT_GRAY image_t as a CV_8UC1 (a copy). Throws
/// std::invalid_argument naming the problem for another pixel format, a
/// non-positive size, row_stride < width, or size != height · row_stride.
cv::Mat grey_from_lcm_image(const image_t& msg);

/// A CV_8UC1 target mask as mask_t (segmenter, the simulator's true mask).
/// Throws std::invalid_argument for any other type or an empty mask.
mask_t to_lcm_mask(const cv::Mat& mask, int64_t utime, int camera_id);

/// The pixels of a mask_t as a CV_8UC1 (a copy). Throws
/// std::invalid_argument naming the problem for a non-positive size or
/// size != width · height != data length.
cv::Mat mask_from_lcm(const mask_t& msg);

}  // namespace vimot
