#pragma once
// The mask filter of one camera (paper 004, Sec. VI-A): a target mask in,
// the target box out. Morphology (erosion then dilation) removes false
// positives, the largest remaining blob gives the raw box, and a box Kalman
// filter (box_kalman.h) smooths it and coasts through frames without one.
// No LCM here: procs/mask_filter wraps it into `vimot-mask-filter`.
// Design and options: docs/mask_filter.md.

#include <Eigen/Core>
#include <cstdint>
#include <string>

#include <opencv2/core.hpp>

#include "common/segmentation/box_kalman.h"
#include "common/segmentation/morphology.h"

namespace vimot {
class Config;
}

namespace vimot::segmentation {

struct MaskFilterOptions {
  MorphologyOptions morphology;
  int min_blob_area_px{20};  // a largest blob smaller than this is no detection
  BoxKalmanOptions kalman;

  /// Throws std::invalid_argument naming the first invalid option.
  void validate() const;

  /// Reads `section` of `cfg` (keys: morphology.{erode_kernel_px,
  /// dilate_kernel_px}, min_blob_area_px, kalman.{the BoxKalmanOptions
  /// fields}); absent keys keep the defaults; a bad value or an unknown key
  /// is a ConfigError naming the file and the key.
  static MaskFilterOptions from_config(const Config& cfg, const std::string& section);
};

/// One frame's result, as vimot.target_box_t carries it.
struct BoxEstimate {
  int64_t utime{0};
  bool raw_valid{false};  // the mask had a blob (fused or not)
  Eigen::Vector4d raw_box{Eigen::Vector4d::Zero()};  // px, [x_min, y_min, width, height]
  bool filtered_valid{false};
  Eigen::Vector4d filtered_box{Eigen::Vector4d::Zero()};  // px
  Eigen::Vector2d filtered_velocity{Eigen::Vector2d::Zero()};  // px/s, box centre
  Eigen::Matrix4d filtered_covariance{Eigen::Matrix4d::Zero()};  // px², in filtered_box's order
  int frames_since_raw{0};  // frames coasted since the last fused detection
  BoxKalmanFilter::Outcome outcome{BoxKalmanFilter::Outcome::kNoTrack};
  int num_blobs{0};  // blobs left after the morphology
};

class MaskFilter {
 public:
  /// Validates the options (std::invalid_argument).
  explicit MaskFilter(const MaskFilterOptions& options);

  /// One mask (CV_8UC1, non-zero = target; an empty or all-zero mask is no
  /// detection) at `utime`, strictly after the previous one (else
  /// std::invalid_argument, as for a mask of another type).
  BoxEstimate process(int64_t utime, const cv::Mat& mask);

  const BoxKalmanFilter& kalman() const { return kalman_; }

 private:
  MaskFilterOptions options_;
  BoxKalmanFilter kalman_;
};

}  // namespace vimot::segmentation
