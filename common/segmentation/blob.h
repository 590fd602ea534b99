#pragma once
// The largest connected blob of a binary mask and its bounding box. The box
// is [x_min, y_min, width, height] in pixels as vimot.target_box_t and the
// rendered simulator's truth (common/sim/renderer.h) carry it: x_min the
// leftmost column, width the number of columns spanned (cv::boundingRect).
// No LCM here.

#include <Eigen/Core>
#include <optional>

#include <opencv2/core.hpp>

namespace vimot::segmentation {

struct Blob {
  Eigen::Vector4d box{Eigen::Vector4d::Zero()};  // px, [x_min, y_min, width, height]
  int area_px{0};                                // pixels in the blob
  int num_blobs{0};                              // blobs in the mask (8-connected), this one included
};

/// The 8-connected blob with the most pixels (the first in scan order on a
/// tie) if it has at least `min_area_px`; nullopt for an empty mask or no
/// blob that large. Throws std::invalid_argument unless CV_8UC1.
std::optional<Blob> largest_blob(const cv::Mat& binary, int min_area_px);

/// Intersection over union of two boxes [x_min, y_min, width, height]
/// (0 when they do not overlap or one is empty).
double box_iou(const Eigen::Vector4d& a, const Eigen::Vector4d& b);

}  // namespace vimot::segmentation
