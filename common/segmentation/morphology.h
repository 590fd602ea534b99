#pragma once
// Mask clean-up before the box is taken (paper 004, Sec. VI-A): erosion
// removes specks and thin false-positive structures a network leaves, the
// dilation that follows (a morphological opening) gives the surviving
// blobs back their extent. No LCM here.

#include <opencv2/core.hpp>

namespace vimot::segmentation {

struct MorphologyOptions {
  int erode_kernel_px{5};   // side of the square erosion kernel (odd; 1 = no erosion)
  int dilate_kernel_px{5};  // side of the square dilation kernel (odd; 1 = no dilation)
  /// Throws std::invalid_argument naming the first invalid option.
  void validate() const;
};

/// A CV_8UC1 mask (non-zero = target) binarised to 0/255, eroded then
/// dilated. Throws std::invalid_argument for another type or an empty mask.
cv::Mat open_mask(const cv::Mat& mask, const MorphologyOptions& options);

}  // namespace vimot::segmentation
