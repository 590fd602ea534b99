#include "common/segmentation/blob.h"

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

}  // namespace vimot::segmentation
