#include "common/segmentation/blob.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

namespace vimot::segmentation {

std::optional<Blob> largest_blob(const cv::Mat& binary, int min_area_px) {
  if (binary.empty() || binary.type() != CV_8UC1) {
    throw std::invalid_argument("largest_blob: expected a non-empty 8-bit single-channel mask, got type " +
                                std::to_string(binary.type()));
  }
  // Most frames of a tracked target are a single blob or none: skip the
  // labelling when nothing is set.
  if (cv::countNonZero(binary) == 0) return std::nullopt;
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(binary, labels, stats, centroids, 8, CV_32S);
  int best = 0;  // label 0 is the background
  for (int i = 1; i < n; ++i) {
    if (best == 0 || stats.at<int>(i, cv::CC_STAT_AREA) > stats.at<int>(best, cv::CC_STAT_AREA)) best = i;
  }
  if (best == 0 || stats.at<int>(best, cv::CC_STAT_AREA) < min_area_px) return std::nullopt;
  Blob b;
  b.box << stats.at<int>(best, cv::CC_STAT_LEFT), stats.at<int>(best, cv::CC_STAT_TOP),
      stats.at<int>(best, cv::CC_STAT_WIDTH), stats.at<int>(best, cv::CC_STAT_HEIGHT);
  b.area_px = stats.at<int>(best, cv::CC_STAT_AREA);
  b.num_blobs = n - 1;
  return b;
}

double box_iou(const Eigen::Vector4d& a, const Eigen::Vector4d& b) {
  const double w = std::min(a(0) + a(2), b(0) + b(2)) - std::max(a(0), b(0));
  const double h = std::min(a(1) + a(3), b(1) + b(3)) - std::max(a(1), b(1));
  if (w <= 0.0 || h <= 0.0) return 0.0;
  return w * h / (a(2) * a(3) + b(2) * b(3) - w * h);
}

}  // namespace vimot::segmentation
