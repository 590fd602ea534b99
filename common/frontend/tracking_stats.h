#pragma once
// Quality figures of a feature track stream, from the tracker's output and
// the rig calibration alone (the benchmark and the EuRoC test use them):
// static features per frame, track length, and the stereo epipolar error of
// the undistorted points against the calibrated extrinsics. No LCM here.

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <vector>

#include "common/camera/camera_model.h"
#include "common/types/sensor_data.h"

namespace vimot::frontend {

struct TrackingFigures {
  int frames{0};
  /// Fewest static features in camera 0 over every frame after the first
  /// (the first can only hold fresh detections); 0 with < 2 frames.
  int min_static_per_frame{0};
  double mean_static_per_frame{0.0};
  double mean_target_per_frame{0.0};  // camera 0
  /// Median over static tracks of the frames each was seen in (any camera).
  double median_track_length{0.0};
  /// Median over stereo observations (static, same id in both cameras in a
  /// frame) of the distance, in cam1 pixels, of the right point from the
  /// epipolar line of the left one; NaN without stereo observations.
  double median_epipolar_px{0.0};
  std::size_t stereo_observations{0};
};

class TrackingStats {
 public:
  /// `cameras`: the calibration the frames were tracked with (1 or 2).
  explicit TrackingStats(const std::vector<CameraCalibration>& cameras);

  void add(const CameraFrame& frame);
  TrackingFigures figures() const;

  /// Distance in cam1 pixels of the cam1 point `x1` from the epipolar line
  /// of the cam0 point `x0` (both normalized), from the calibrated
  /// extrinsics: E = [p_C0inC1]x R_C0toC1.
  double epipolar_error_px(const Eigen::Vector2d& x0, const Eigen::Vector2d& x1) const;

 private:
  std::vector<CameraCalibration> cameras_;
  Eigen::Matrix3d E_{Eigen::Matrix3d::Zero()};
  double focal1_{0.0};
  std::vector<int> static_per_frame_;
  int64_t target_observations_{0};  // camera 0
  std::map<int64_t, int> track_length_;
  std::vector<double> epipolar_px_;
};

/// Median of a copy of `v` (mean of the middle two for an even count); NaN if empty.
double median(std::vector<double> v);

}  // namespace vimot::frontend
