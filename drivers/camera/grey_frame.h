#pragma once
// A delivered frame as the image vimot publishes: 8-bit grey at the
// configured size.

#include <opencv2/core.hpp>
#include <string>

namespace vimot::camera {

/// `frame` (CV_8UC1 as is, CV_8UC3 BGR or CV_8UC4 BGRA to luma with
/// OpenCV's BT.601 weights 0.299 R + 0.587 G + 0.114 B) as a CV_8UC1 of
/// width × height. A frame of another size is scaled (INTER_AREA) when
/// `resize`, else CameraError naming `camera` and both sizes; another pixel
/// type is a CameraError naming it.
cv::Mat to_grey(const cv::Mat& frame, int width, int height, bool resize, const std::string& camera);

}  // namespace vimot::camera
